"""The guide's Python page (docs/src/python.md) is real: its ```python blocks run in order in
one namespace (as a notebook), in a scratch folder that sees the repository's examples/,
and what each block prints must be the ```text block under it, line for line."""

import contextlib
import io
import os
import re

from conftest import ROOT

PAGE = ROOT / "docs" / "src" / "python.md"


def cells(text):
    """(line, code, expected output or None) per python block, in page order."""
    blocks = re.findall(r"^```(\w*)\n(.*?)^```\n", text, flags=re.S | re.M)
    starts = [m.start() for m in re.finditer(r"^```(\w*)\n(.*?)^```\n", text, flags=re.S | re.M)]
    out = []
    for i, (lang, body) in enumerate(blocks):
        if lang != "python":
            continue
        expected = None
        if i + 1 < len(blocks) and blocks[i + 1][0] == "text":
            between = text[starts[i]:starts[i + 1]].count("```")
            if between == 2:
                expected = blocks[i + 1][1]
        out.append((text[:starts[i]].count("\n") + 1, body, expected))
    return out


def test_page_blocks_run_and_print_what_the_page_shows(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    os.symlink(ROOT / "examples", tmp_path / "examples")
    namespace = {}
    found = cells(PAGE.read_text())
    assert len(found) >= 5
    for line, code, expected in found:
        printed = io.StringIO()
        with contextlib.redirect_stdout(printed):
            exec(compile(code, f"{PAGE}:{line}", "exec"), namespace)
        if expected is not None:
            assert printed.getvalue().rstrip("\n") == expected.rstrip("\n"), (
                f"docs/src/python.md line {line}: the block prints\n{printed.getvalue()}")
