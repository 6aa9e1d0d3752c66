"""CI's figure check (.ci/compare_figures.py): a changed figure fails, an identical one passes."""

import importlib.util
import shutil
import subprocess
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pytest  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
spec = importlib.util.spec_from_file_location(
    "compare_figures", REPO / ".ci" / "compare_figures.py"
)
compare_figures = importlib.util.module_from_spec(spec)
spec.loader.exec_module(compare_figures)


def draw(path: Path, label: str = "a", shift: float = 0.0) -> Path:
    fig, ax = plt.subplots(figsize=(2, 1.5), dpi=100)
    ax.plot([0, 1, 2], [0.0 + shift, 1.0, 0.5], label=label)
    ax.legend()
    fig.savefig(path, metadata={"Software": None})
    plt.close(fig)
    return path


@pytest.fixture
def folders(tmp_path):
    committed, regenerated = tmp_path / "committed", tmp_path / "figures"
    committed.mkdir()
    regenerated.mkdir()
    draw(committed / "fig1.png")
    draw(committed / "fig2.png", label="b")
    return committed, regenerated, tmp_path / "work"


def test_identical_figures_pass(folders):
    committed, regenerated, work = folders
    for png in committed.glob("*.png"):
        shutil.copyfile(png, regenerated / png.name)
    assert compare_figures.compare_folders(committed, regenerated, work, 0.1) == []
    assert (
        compare_figures.main(
            ["--figures", str(regenerated), "--committed", str(committed), "--work", str(work)]
        )
        == 0
    )


def test_changed_figure_fails_naming_it_and_its_diff_image(folders, capsys):
    committed, regenerated, work = folders
    shutil.copyfile(committed / "fig1.png", regenerated / "fig1.png")
    draw(regenerated / "fig2.png", label="b", shift=0.2)  # one curve moved
    problems = compare_figures.compare_folders(committed, regenerated, work, 0.1)
    assert len(problems) == 1 and problems[0].startswith("fig2.png: RMS"), problems
    diff = Path(problems[0].split("diff image: ")[1].rstrip(")"))
    assert diff.is_file() and diff.parent == work
    assert not list(regenerated.glob("*diff*"))  # nothing written into the figures folder
    argv = ["--figures", str(regenerated), "--committed", str(committed), "--work", str(work)]
    assert compare_figures.main(argv) == 1
    assert "fig2.png: RMS" in capsys.readouterr().err


def test_missing_new_and_resized_figures_fail(folders):
    committed, regenerated, work = folders
    draw(regenerated / "fig3.png")  # not committed; fig1 and fig2 not regenerated
    problems = compare_figures.compare_folders(committed, regenerated, work, 0.1)
    assert "fig1.png: committed but not regenerated" in problems
    assert "fig3.png: regenerated but not committed" in problems
    fig, ax = plt.subplots(figsize=(3, 1.5), dpi=100)  # a different size
    fig.savefig(regenerated / "fig1.png")
    plt.close(fig)
    problems = compare_figures.compare_folders(committed, regenerated, work, 0.1)
    assert any(p.startswith("fig1.png:") and "size" in p for p in problems), problems


def test_committed_figures_come_from_git_head(tmp_path):
    """Default mode: the reference is git's HEAD, whatever the working tree holds."""
    git = ["git", "-c", "user.name=t", "-c", "user.email=t@t", "-C", str(tmp_path)]
    subprocess.run([*git, "init", "-q"], check=True)
    (tmp_path / "figures" / "benchmarks").mkdir(parents=True)
    draw(tmp_path / "figures" / "fig1.png")
    draw(tmp_path / "figures" / "benchmarks" / "timing.png")  # never compared
    subprocess.run([*git, "add", "figures"], check=True)
    subprocess.run([*git, "commit", "-qm", "figures"], check=True)
    out = tmp_path / "head"
    out.mkdir()
    written = compare_figures.committed_from_git(tmp_path, "figures", out)
    assert [p.name for p in written] == ["fig1.png"]
    assert written[0].read_bytes() == (tmp_path / "figures" / "fig1.png").read_bytes()
