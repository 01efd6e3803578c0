"""Runs the ```python blocks of docs/python.md in order, in one namespace, as a notebook; and
those of docs/guide.md, from docs/snippets/ (where the guide's effect file is)."""
import re


def python_blocks(path):
    return re.findall(r"^```python\n(.*?)^```", path.read_text(), flags=re.S | re.M)


def run_blocks(blocks, page):
    namespace: dict = {}
    for i, code in enumerate(blocks):
        exec(compile(code, f"{page} block {i + 1}", "exec"), namespace)


def test_python_md_runs(source_dir, capsys):
    blocks = python_blocks(source_dir / "docs" / "python.md")
    assert len(blocks) >= 4
    run_blocks(blocks, "docs/python.md")
    assert "alive, lowest y" in capsys.readouterr().out


def test_guide_python_runs(source_dir, capsys, monkeypatch):
    blocks = python_blocks(source_dir / "docs" / "guide.md")
    assert len(blocks) >= 1
    monkeypatch.chdir(source_dir / "docs" / "snippets")
    run_blocks(blocks, "docs/guide.md")
    assert "flames:" in capsys.readouterr().out
