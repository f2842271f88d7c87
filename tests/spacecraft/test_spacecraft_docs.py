"""Every Python block of the spacecraft pages runs as a script (each in a fresh namespace)."""

import re
from pathlib import Path

import pytest

DOCS = Path(__file__).resolve().parents[2] / "docs"
PAGES = ("spacecraft.md", "spacecraft_environment.md", "passive_stability.md")
BLOCKS = [(page, k, code) for page in PAGES
          for k, code in enumerate(re.findall(r"```python\n(.*?)```", (DOCS / page).read_text(encoding="utf-8"),
                                              flags=re.S))]


def test_every_page_has_python():
    assert {page for page, _, _ in BLOCKS} == set(PAGES)


@pytest.mark.slow  # each block compiles its spacecraft model on first use
@pytest.mark.parametrize("page, k, code", BLOCKS, ids=[f"{page}:{k}" for page, k, _ in BLOCKS])
def test_python_block_runs(page, k, code, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    exec(compile(code, f"{page} block {k}", "exec"), {"__name__": "__main__"})  # the project's own text
