"""Runs the ```python blocks of docs/python.md in order, in one namespace, as a notebook."""
import re


def test_python_md_runs(source_dir, capsys):
    text = (source_dir / "docs" / "python.md").read_text()
    blocks = re.findall(r"^```python\n(.*?)^```", text, flags=re.S | re.M)
    assert len(blocks) >= 4
    namespace: dict = {}
    for i, code in enumerate(blocks):
        exec(compile(code, f"docs/python.md block {i + 1}", "exec"), namespace)
    assert "alive, lowest y" in capsys.readouterr().out
