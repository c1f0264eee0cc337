"""The cache of dial's dataclasses' code (:mod:`dial.codecache`): the same functions as
Python makes, across processes; a damaged, foreign or stale entry is never used."""

from __future__ import annotations

import dataclasses
import inspect
import marshal
import os
import subprocess
import sys
import types
from collections.abc import Iterator
from pathlib import Path

import pytest

from dial import codecache
from dial.codecache import CodeCache

from .conftest import ROOT

CLASS = """
from __future__ import annotations
from dataclasses import dataclass, field

@dataclass(frozen=True, order=True)
class Probe:
    name: str
    count: int = 0
    tags: tuple[str, ...] = field(default_factory=tuple)
"""
METHODS = ("__init__", "__repr__", "__eq__", "__lt__", "__hash__", "__setattr__")


def _probe(module: str) -> type:
    """The class ``Probe`` made in a fresh module of that name."""
    space = types.ModuleType(module)
    sys.modules[module] = space
    try:
        exec(CLASS, space.__dict__)
        return space.__dict__["Probe"]  # type: ignore[no-any-return]
    finally:
        del sys.modules[module]


@pytest.fixture
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[CodeCache]:
    """A cache of its own installed in this process, in a fresh folder."""
    fresh = CodeCache(tmp_path / "code" / f"{codecache.file_name()}.marshal")
    monkeypatch.setattr(codecache, "_CACHE", [fresh])
    monkeypatch.setattr(dataclasses, "exec", codecache._exec, raising=False)
    yield fresh


def test_the_methods_are_those_python_makes(cache: CodeCache) -> None:
    with pytest.MonkeyPatch.context() as unpatched:  # as Python makes them
        unpatched.delattr(dataclasses, "exec")
        plain = _probe("dial.probe")
    elsewhere, cached = _probe("probe_elsewhere"), _probe("dial.probe")
    assert cache._used, "dial's class went through the cache"
    made = [m for code in cache._used.values() for m in _nested(code)]
    assert all(any(c is code for c in made) for code in _codes(cached))
    assert not any(any(c is code for c in made) for code in _codes(elsewhere))
    # The same bytecode, constants, names, lines and flags (not codecache's future import).
    assert _codes(cached) == _codes(plain) == _codes(elsewhere)
    for method in METHODS:  # annotations are the class's objects, not strings
        assert getattr(cached, method).__annotations__ == getattr(plain, method).__annotations__
    a, b = cached("a", 1), cached("b")
    assert (a < b, repr(a), a == cached("a", 1), hash(a) == hash(cached("a", 1))) == (
        True,
        "Probe(name='a', count=1, tags=())",
        True,
        True,
    )
    with pytest.raises(dataclasses.FrozenInstanceError):
        a.count = 2  # type: ignore[misc]


def _nested(code: types.CodeType) -> Iterator[types.CodeType]:
    """The code objects in ``code`` (a text's: ``__create_fn__``, then the method)."""
    for const in code.co_consts:
        if isinstance(const, types.CodeType):
            yield const
            yield from _nested(const)


def _codes(cls: type) -> list[types.CodeType]:
    return [inspect.unwrap(getattr(cls, m)).__code__ for m in METHODS]  # __repr__ is wrapped


def test_a_second_process_reads_what_the_first_compiled(cache: CodeCache) -> None:
    _probe("dial.probe")
    cache.save()
    assert cache.path.is_file()
    again = CodeCache(cache.path)
    source = next(iter(cache._used))
    assert again.code(source) == compile(source, "<string>", "exec", dont_inherit=True)
    assert not again._new  # read, not compiled: nothing to write at exit


@pytest.mark.parametrize("content", [b"", b"\x00garbage", marshal.dumps([1, 2])])
def test_a_damaged_file_is_compiled_again_and_replaced(cache: CodeCache, content: bytes) -> None:
    cache.path.parent.mkdir(parents=True)
    cache.path.write_bytes(content)
    cls = _probe("dial.probe")
    assert cls("x").name == "x" and cache._new
    cache.save()
    assert all(type(v) is types.CodeType for v in marshal.loads(cache.path.read_bytes()).values())


def test_an_entry_that_is_not_code_is_not_used(cache: CodeCache) -> None:
    source = "def __create_fn__():\n def f(): return 1\n return f"
    cache.path.parent.mkdir(parents=True)
    cache.path.write_bytes(marshal.dumps({source: "not code", "other": 3}))
    assert cache.code(source) == compile(source, "<string>", "exec", dont_inherit=True)
    cache.save()
    assert marshal.loads(cache.path.read_bytes()) == {source: cache.code(source)}


def test_an_edited_class_or_another_python_finds_no_entry(
    cache: CodeCache, monkeypatch: pytest.MonkeyPatch
) -> None:
    old = "def __create_fn__():\n def f(): return 1\n return f"
    new = old.replace("1", "2")  # the class edited: another text
    cache.path.parent.mkdir(parents=True)
    cache.path.write_bytes(marshal.dumps({old: compile(old, "<string>", "exec")}))
    assert cache.code(new) == compile(new, "<string>", "exec", dont_inherit=True)
    name = codecache.file_name()
    monkeypatch.setattr(codecache, "MAGIC_NUMBER", b"\x00\x01\r\n")  # another bytecode
    assert codecache.file_name() != name
    monkeypatch.setattr(marshal, "version", marshal.version + 1)
    assert len({name, codecache.file_name()}) == 2


def _run(program: str, cache: str) -> str:
    env = dict(os.environ, DIAL_CACHE=cache)
    return subprocess.run(
        [sys.executable, "-c", program],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        check=True,
    ).stdout.strip()


def test_processes_share_the_file_and_off_installs_nothing(tmp_path: Path) -> None:
    program = (
        "import dataclasses, dial.parser.script, dial.codecache as c; "
        "print(dataclasses.__dict__.get('exec') is c._exec, c.installed() and c.installed()._new)"
    )
    assert _run(program, str(tmp_path)) == "True True"  # compiled, and written at exit
    (written,) = (tmp_path / "code").iterdir()
    before = written.read_bytes()
    assert _run(program, str(tmp_path)) == "True False"  # all read from the file
    assert written.read_bytes() == before  # nothing new: not written again
    assert _run(program, "off") == "False None"
