"""A checked script is typed all the way down: no ``Any`` in ``Script``, ``EventDef`` or the
types of their fields (the AST, the timeline, the argument records of every instruction)."""

from __future__ import annotations

import dataclasses
import typing
from collections.abc import Iterator

import dial.instructions.catalogue  # noqa: F401  (every record class is defined)
from dial.instructions.base import Args
from dial.parser.script import EventDef, Script


def _records(cls: type[Args] = Args) -> Iterator[type[Args]]:
    for sub in cls.__subclasses__():
        yield sub
        yield from _records(sub)


def _any_in(root: type, seen: set[type]) -> list[str]:
    """Where ``Any`` appears in the field types of ``root`` and the dial classes they name."""
    found: list[str] = []
    todo = [root]
    while todo:
        cls = todo.pop()
        if cls in seen:
            continue
        seen.add(cls)
        hints = typing.get_type_hints(cls) if dataclasses.is_dataclass(cls) else {}
        for name, hint in hints.items():
            stack = [hint]
            while stack:
                t = stack.pop()
                if t is typing.Any:
                    found.append(f"{cls.__qualname__}.{name}")
                stack += typing.get_args(t)
                origin = typing.get_origin(t) or t
                if isinstance(origin, type) and origin.__module__.startswith("dial."):
                    todo.append(origin)
    return found


def test_no_any_in_a_checked_scripts_types() -> None:
    roots = [Script, EventDef, *_records()]
    assert len(roots) > 15  # the records of every instruction
    seen: set[type] = set()
    assert [where for root in roots for where in _any_in(root, seen)] == []
    assert Script in seen and EventDef in seen


def test_the_check_finds_an_any() -> None:
    @dataclasses.dataclass
    class Loose:
        args: typing.Mapping[str, typing.Any]

    assert _any_in(Loose, set()) == ["test_the_check_finds_an_any.<locals>.Loose.args"]
