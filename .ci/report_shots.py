"""Screenshots of the Snakemake report in a real browser: the check behind `make report-shots`.

The report is a single-page app (React): its pages exist only after clicks. Debian's headless
Chromium, driven by selenium through Debian's chromium-driver (both installed with apt-get when
missing and running as root), opens report.html and takes:

- ``front.png``: the front page, after scrolling its pane to the top; the script fails if the
  page's first line is not visible there (a long front page used to overflow above the pane's
  top, out of the scrollbar's reach: see workflow/report/style.css);
- ``figure-1.png``, ``figure-2.png``: two figure pages, reached as a reader does: a category in
  the menu, a figure's subcategory, then the "view" (eye) button of its first PNG result;
- ``reproduction.png``: the reproduction table's own page (category Reproduction).

Usage: python .ci/report_shots.py REPORT.html OUTDIR. Look at the PNGs: they are the check.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

CHROMIUM = "/usr/bin/chromium"
CHROMEDRIVER = "/usr/bin/chromedriver"
# Flags that work in a container without a display or network (fresh --user-data-dir each run).
FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--disable-dev-shm-usage",
    "--window-size=1400,1000",
]
# The two figure pages: (category, subcategory) by the start of their menu labels.
FIGURES = (("Sect. 2", "Fig. 2"), ("Sect. 3.4", "Fig. 7"))
TIMEOUT_S = 60


def ensure_browser() -> None:
    if Path(CHROMIUM).exists() and Path(CHROMEDRIVER).exists():
        return
    if os.geteuid() != 0:
        sys.exit("report_shots: needs Debian's chromium and chromium-driver (apt-get install)")
    apt = ["apt-get", "install", "-y", "--no-install-recommends", "chromium", "chromium-driver"]
    env = {**os.environ, "DEBIAN_FRONTEND": "noninteractive"}
    if subprocess.run(apt, env=env).returncode != 0:
        subprocess.run(["apt-get", "update"], env=env, check=True)
        subprocess.run(apt, env=env, check=True)


def wait_for(driver, condition, what: str):
    deadline = time.monotonic() + TIMEOUT_S
    while time.monotonic() < deadline:
        found = condition()
        if found:
            return found
        time.sleep(0.25)
    driver.save_screenshot(str(Path(tempfile.gettempdir()) / "report-shots-failure.png"))
    sys.exit(f"report_shots: timed out waiting for {what}")


def click_text(driver, text: str, prefix: bool = False):
    """Click the menu entry (an <a>) whose text is ``text`` (or starts with it)."""
    from selenium.webdriver.common.by import By

    def find():
        for link in driver.find_elements(By.CSS_SELECTOR, "a"):
            label = link.text.strip()
            if label and (label.startswith(text) if prefix else label == text):
                return link
        return None

    link = wait_for(driver, find, f"a menu entry {text!r}")
    label = link.text.strip()
    link.click()
    time.sleep(0.5)
    return label


def figure_rows(driver):
    """Rows of the results list that show a figure (a view button; tables only download)."""
    from selenium.webdriver.common.by import By

    rows = []
    for row in driver.find_elements(By.CSS_SELECTOR, "tr"):
        if "table" in row.text or not row.find_elements(By.CSS_SELECTOR, 'a[href="#"]'):
            continue
        rows.append(row)
    return rows


def content_pane(driver):
    from selenium.webdriver.common.by import By

    panes = driver.find_elements(By.CSS_SELECTOR, "div.grow.h-screen.overflow-auto")
    return panes[0] if panes else None


def main(argv: list[str]) -> int:
    if len(argv) != 2:
        sys.exit(__doc__)
    report, outdir = Path(argv[0]).resolve(), Path(argv[1])
    if not report.is_file():
        sys.exit(f"report_shots: {report} not found (make report)")
    outdir.mkdir(parents=True, exist_ok=True)
    ensure_browser()

    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    from selenium.webdriver.common.by import By

    profile = tempfile.mkdtemp(prefix="report-shots-profile-")
    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for flag in [*FLAGS, f"--user-data-dir={profile}"]:
        options.add_argument(flag)
    driver = webdriver.Chrome(service=Service(CHROMEDRIVER), options=options)
    try:
        driver.get(report.as_uri())
        wait_for(driver, lambda: driver.find_elements(By.CSS_SELECTOR, "a"), "the menu")
        pane = wait_for(driver, lambda: content_pane(driver), "the content pane")

        # Front page: scroll its pane to the top; its first paragraph must be inside the window.
        driver.execute_script("arguments[0].scrollTop = 0;", pane)
        time.sleep(0.5)
        first = wait_for(
            driver,
            lambda: driver.find_elements(By.CSS_SELECTOR, "div.prose > *"),
            "the front page's text",
        )[0]
        top = driver.execute_script("return arguments[0].getBoundingClientRect().top;", first)
        path = outdir / "front.png"
        driver.save_screenshot(str(path))
        print(f"{path}: front page, first line at y = {top:.0f} px")
        if top < 0:
            sys.exit(f"report_shots: the front page's first line is above the window ({top} px)")

        for i, (category_prefix, subcategory_prefix) in enumerate(FIGURES, start=1):
            category = click_text(driver, category_prefix, prefix=True)
            # A category with one subcategory lists its results at once; others list figures.
            time.sleep(1.0)
            if figure_rows(driver):
                subcategory = "(its only subcategory)"
            else:
                subcategory = click_text(driver, subcategory_prefix, prefix=True)
            row = wait_for(driver, lambda: figure_rows(driver), "a figure's row in the results")[0]
            label = " ".join(row.text.split())
            row.find_elements(By.CSS_SELECTOR, 'a[href="#"]')[0].click()  # the eye: view it
            wait_for(driver, lambda: driver.find_elements(By.CSS_SELECTOR, "img"), "the figure")
            time.sleep(1.0)
            path = outdir / f"figure-{i}.png"
            driver.save_screenshot(str(path))
            print(f"{path}: {category} > {subcategory} > {label}")
            driver.get(report.as_uri())  # back to the start for the next one
            wait_for(driver, lambda: driver.find_elements(By.CSS_SELECTOR, "a"), "the menu")

        # The reproduction table's own page (an HTML result, shown in the content pane).
        click_text(driver, "Reproduction")
        # Its two results (CSV, page) differ in the label "quantity": the report shows a toggle.
        toggle = wait_for(
            driver,
            lambda: driver.find_elements(By.XPATH, "//label[contains(., 'readable page')]"),
            "the toggle to the reproduction page",
        )[0]
        toggle.click()
        time.sleep(0.5)
        row = wait_for(driver, lambda: figure_rows(driver), "the reproduction page's row")[0]
        row.find_elements(By.CSS_SELECTOR, 'a[href="#"]')[0].click()
        wait_for(driver, lambda: driver.find_elements(By.CSS_SELECTOR, "iframe"), "the page")
        time.sleep(1.5)
        path = outdir / "reproduction.png"
        driver.save_screenshot(str(path))
        print(f"{path}: Reproduction > {' '.join(toggle.text.split())}")
        return 0
    finally:
        driver.quit()
        shutil.rmtree(profile, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
