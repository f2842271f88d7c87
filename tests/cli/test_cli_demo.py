"""`tumble demo`: one command per row of the demo table, the list, the old spellings of racket and polhode (they
warn until 0.5 and write the same files), a bad option or name in one `error:` line."""

import os
import re
import stat
import subprocess
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

import tumble
from helpers import assert_one_line_error, assert_same_run
from tumble.cli import app
from tumble.viz.demos import DEMOS

SRC = Path(__file__).resolve().parents[2] / "src"
DOCS = Path(__file__).resolve().parents[2] / "docs"
runner = CliRunner()


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args])


def files(directory: Path) -> dict[str, bytes]:
    return {path.name: path.read_bytes() for path in sorted(directory.iterdir())}


@pytest.mark.parametrize("args", [[], ["--list"]], ids=["no name", "--list"])
def test_the_list_names_every_demo_of_the_table_in_one_line_each(args):
    result = invoke("demo", *args)
    assert result.exit_code == 0, result.output
    lines = result.stdout.splitlines()
    assert [line.split()[0] for line in lines] == list(DEMOS)
    for line, demo in zip(lines, DEMOS.values()):
        assert line.endswith(demo.help.splitlines()[0])  # what it shows: the first line of its help


@pytest.mark.parametrize("name", DEMOS)
def test_every_demo_has_a_command_with_its_options(name):
    result = invoke("demo", name, "--help")
    assert result.exit_code == 0, result.output
    assert f"Usage: tumble demo {name} [OPTIONS]" in result.stdout
    for flag in ("--output", *(option.flag for option in DEMOS[name].options)):
        assert flag in result.stdout


@pytest.mark.parametrize("name", DEMOS)
def test_a_bad_option_of_any_demo_is_one_error_line_naming_it(name, tmp_path):
    result = invoke("demo", name, "-o", tmp_path, "--colour", "red")
    assert_one_line_error(result, f"--colour: not an option of tumble demo {name} (its options: -o/--output")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("name", [name for name, demo in DEMOS.items() if demo.options])
def test_a_bad_option_value_is_one_error_line_naming_the_option(name, tmp_path):
    flag = DEMOS[name].options[0].flag
    assert_one_line_error(invoke("demo", name, "-o", tmp_path, flag, "fast"), f"{flag}: ")
    assert_one_line_error(invoke("demo", name, "-o", tmp_path, flag, "-1"),
                          f"{flag}: must be a finite number > 0, got -1.0")
    assert list(tmp_path.iterdir()) == []


def test_a_name_that_is_no_demo_is_one_error_line_naming_the_demos():
    assert_one_line_error(invoke("demo", "racquet"), f"racquet: not a demo of tumble demo (the demos: "
                                                     f"{', '.join(DEMOS)})")


@pytest.mark.parametrize("name", DEMOS)
def test_every_demo_checks_each_of_its_files_before_it_runs(name, tmp_path):
    # a FIFO where the demo's last file goes: refused before any work (a demo that ran would block on it)
    last = tmp_path / DEMOS[name].files[-1]
    os.mkfifo(last)
    assert_one_line_error(invoke("demo", name, "-o", tmp_path), f"--output: {str(last)!r} is a FIFO")
    assert [(p.name, stat.S_ISFIFO(p.stat().st_mode)) for p in tmp_path.iterdir()] == [(last.name, True)]


def test_the_docs_table_has_every_demo():
    page = (DOCS / "cli.md").read_text(encoding="utf-8")
    rows = re.findall(r"^\| `tumble demo ([a-z0-9-]+)` \|", page, flags=re.MULTILINE)
    assert rows == list(DEMOS)


# -- the demos' files ---------------------------------------------------------------------------------


def test_racket_writes_its_three_files_in_the_directory(tmp_path):
    result = invoke("demo", "racket", "-o", tmp_path, "--duration", 4, "--quiet")
    assert result.exit_code == 0, result.output
    assert list(files(tmp_path)) == sorted(DEMOS["racket"].files)
    assert result.stdout.splitlines()[-1] == ("wrote     " + ", ".join(str(tmp_path / name)
                                                                      for name in DEMOS["racket"].files))
    assert re.search(r"^flips     1 in 4 s\n", result.stdout, flags=re.MULTILINE)  # one flip every 2.98632 s
    assert len(tumble.load(tmp_path / "racket.nc")) == 4 * 200 + 1


def test_polhode_writes_its_two_files_in_the_directory(tmp_path):
    result = invoke("demo", "polhode", "-o", tmp_path)
    assert result.exit_code == 0, result.output
    assert list(files(tmp_path)) == sorted(DEMOS["polhode"].files)


# -- the old spellings, until 0.5 ---------------------------------------------------------------------


def test_the_old_racket_spelling_warns_and_writes_the_same_files(tmp_path):
    new, old = tmp_path / "new", tmp_path / "old"
    new.mkdir(), old.mkdir()
    assert invoke("demo", "racket", "-o", new, "--duration", 4).exit_code == 0
    result = invoke("demo", "racket", "-o", old / "r.nc", "--plot", old / "r.png", "--duration", 4)
    assert result.exit_code == 0, result.output
    assert result.stderr == ("warning: `tumble demo racket -o FILE.nc --plot FILE.png` is deprecated and removed in "
                             "0.5: use `tumble demo racket -o DIRECTORY` (writes racket.nc, racket.png, racket.html "
                             "there)\n")
    assert f"wrote     {old / 'r.nc'}, {old / 'r.png'}, {old / 'r.html'}" in result.stdout
    written, expected = files(old), files(new)
    assert list(written) == ["r.html", "r.nc", "r.png"]
    assert_same_run(tumble.load(old / "r.nc"), tumble.load(new / "racket.nc"))
    assert written["r.png"] == expected["racket.png"] and written["r.html"] == expected["racket.html"]


def test_the_old_racket_spelling_without_plot_writes_racket_png_here(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    result = invoke("demo", "racket", "-o", "run.nc", "--duration", 1)
    assert result.exit_code == 0, result.output
    assert result.stderr.startswith("warning: `tumble demo racket -o FILE.nc --plot FILE.png` is deprecated")
    assert list(files(tmp_path)) == ["racket.html", "racket.png", "run.nc"]


def test_the_old_polhode_spelling_warns_and_writes_the_same_files(tmp_path):
    new, old = tmp_path / "new", tmp_path / "old"
    new.mkdir(), old.mkdir()
    assert invoke("demo", "polhode", "-o", new).exit_code == 0
    result = invoke("demo", "polhode", "-o", old / "p.png")
    assert result.exit_code == 0, result.output
    assert result.stderr == ("warning: `tumble demo polhode -o FILE.png` is deprecated and removed in 0.5: use "
                             "`tumble demo polhode -o DIRECTORY` (writes polhode.png, polhode.html there)\n")
    assert f"wrote     {old / 'p.png'}, {old / 'p.html'}" in result.stdout
    assert files(old) == {"p.html": files(new)["polhode.html"], "p.png": files(new)["polhode.png"]}


@pytest.mark.slow  # a new process simulates the README's 20 s of the T-handle (about 5 CPU s with a warm cache)
def test_the_readme_first_command_writes_the_three_files_here(tmp_path):
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    done = subprocess.run([sys.executable, "-m", "tumble", "demo", "racket"], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert "warning" not in done.stderr
    assert done.stdout.splitlines()[-1] == "wrote     racket.nc, racket.png, racket.html"
    assert list(files(tmp_path)) == ["racket.html", "racket.nc", "racket.png"]
