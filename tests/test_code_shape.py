"""Modules a newcomer can read: at most 400 lines each, functions at most 60 lines.

The exceptions are declarative tables: a command's argparse options (``add_parser``,
``build_parser``) read as a list, one option after another, however long.
"""

from __future__ import annotations

import ast

from .conftest import ROOT

MAX_MODULE = 400
MAX_FUNCTION = 60
TABLES = {"add_parser", "build_parser"}  # argparse option lists


def _sources() -> list[tuple[str, str]]:
    return [
        (str(path.relative_to(ROOT)), path.read_text(encoding="utf-8"))
        for path in sorted((ROOT / "dial").rglob("*.py"))
    ]


def test_no_module_is_over_400_lines() -> None:
    long = {name: text.count("\n") for name, text in _sources() if text.count("\n") > MAX_MODULE}
    assert long == {}


def test_no_function_is_over_60_lines_except_option_tables() -> None:
    long = {}
    for name, text in _sources():
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                lines = (node.end_lineno or node.lineno) - node.lineno + 1
                if lines > MAX_FUNCTION and node.name not in TABLES:
                    long[f"{name}:{node.lineno} {node.name}"] = lines
    assert long == {}
