"""MkDocs hook: publish the committed figures with the site, so the pages can show them.

The pages link the figures as ``../figures/<name>.png`` (right when a page is read as a source on
the forge, docs/ being next to figures/). MkDocs sees only docs/, so this hook adds
``figures/*.png`` to the site under ``figures/`` and rewrites those links for the page's place in
the site: every link is then checked by ``mkdocs build --strict`` like any other.
"""

from __future__ import annotations

import posixpath
import re
from pathlib import Path

from mkdocs.structure.files import File

ROOT = Path(__file__).resolve().parent.parent
FIGURE_LINK = re.compile(r"\]\((?:\.\./)+figures/")


def on_files(files, config):
    for png in sorted((ROOT / "figures").rglob("*.png")):
        path = png.relative_to(ROOT).as_posix()
        files.append(
            File(path, src_dir=str(ROOT), dest_dir=config["site_dir"], use_directory_urls=False)
        )
    return files


def on_page_markdown(markdown, page, config, files):
    # From docs/<dir>/page.md the forge link is ../../figures/x.png; in the site the figures sit
    # at the docs root's level, so the link becomes relative to the page's source folder.
    up = posixpath.relpath(".", posixpath.dirname(page.file.src_uri) or ".")
    prefix = "figures/" if up == "." else f"{up}/figures/"
    return FIGURE_LINK.sub("](" + prefix, markdown)
