"""Check a parsed program: bind its events, look up scene names, check conditions and calls.

Everything here is known without the simulator. Checks that need a scene's
world file (unknown pose, location or program) go through a
:data:`~dial.instructions.scene_names.SceneLoader`. The timeline is compiled by
:mod:`dial.parser.compile`, which asks this checker about names.
"""

from __future__ import annotations

import gc
from collections.abc import Iterator, Mapping
from contextlib import contextmanager, suppress
from dataclasses import dataclass, field, replace
from difflib import get_close_matches
from pathlib import Path

from dial.errors import MAX_PROBLEMS, Diagnostic, ScriptError, Span, TooManyProblems, tally
from dial.instructions.base import Instruction, Values
from dial.instructions.catalogue import INSTRUCTIONS, WATCHABLE
from dial.instructions.robot_checks import robot_errors
from dial.instructions.scene_names import SceneLoader, SceneNames, SceneNotFoundError
from dial.instructions.types import EFFECTORS, Contact, Name, Names
from dial.parser.ast import Call, Condition, Definition, ExecLine, Program
from dial.parser.bind import bind
from dial.parser.compile import compile_body, diagram_events
from dial.parser.parse import parse_partial
from dial.parser.script import EventDef, Script


def _hint(name: str, valid: list[str]) -> str:
    close = get_close_matches(name, valid, n=3)
    return f"; did you mean {' or '.join(repr(c) for c in close)}?" if close else ""


def _choices(valid: list[str]) -> str:
    return f" (valid: {', '.join(sorted(valid))})" if valid else " (none are defined)"


class _SceneFailed:
    """The caller's scene did not load (its error is reported): check no names in callees."""


_SCENE_FAILED = _SceneFailed()
_CallerScene = SceneNames | _SceneFailed | None


@dataclass(frozen=True)
class _Context:
    """What a check shares with the checks of the scripts it calls."""

    loader: SceneLoader | None
    scene_override: str | None  # replaces ``@scene`` here and in every called script
    diags: list[Diagnostic] = field(default_factory=list)
    stack: tuple[str, ...] = ()  # resolved paths of the calling scripts, for call cycles
    # The scene of the calling script: a called script runs in its caller's scene.
    caller_scene: _CallerScene = None
    depth: int = 0  # the nesting level of the '@call' that runs this script
    # Checked callees by (path, id of the scene they run in, level): the script (None if it
    # has problems), and the scene, kept alive so that its id stays its own.
    callees: dict[tuple[str, int, int], tuple[Script | None, _CallerScene]] = field(
        default_factory=dict
    )

    def entering(self, origin: Path) -> _Context:
        """The context inside the script at ``origin``."""
        return replace(self, stack=(*self.stack, str(origin.resolve())))


class _Checker:
    def __init__(self, program: Program, source: str, origin: Path, ctx: _Context) -> None:
        self.program, self.seen = program, 0  # the file's problems so far
        self.ctx = ctx
        self.origin = origin  # the real file, for resolving @call and @scene paths
        self.source = source
        self.lines: list[str] | None = None  # split on the first problem: most checks have none
        self.events: dict[str, EventDef] = {}
        self.broken: set[str] = set()  # defined, but the definition has errors
        self.shown: set[str] = set()  # events that appear in a diagram
        self.scene: SceneNames | None = None
        self.scene_failed = False

    def error(self, span: Span, message: str) -> None:
        if self.lines is None:
            self.lines = self.source.split("\n")
        text = self.lines[span.line - 1] if 0 < span.line <= len(self.lines) else ""
        self.ctx.diags.append(Diagnostic(self.program.path, span, message, text))
        self.seen = tally(self.seen + 1, self.ctx.diags, self.program.path, span.line, self.source)

    def run(self, seen: int = 0) -> Script:
        self.seen = tally(seen, self.ctx.diags, self.program.path, 0, self.source)
        self.load_scene()
        for d in self.program.definitions:
            self.define(d)
        self.shown = diagram_events(self.program.body)
        condition_only = frozenset(
            e for e in self.events if e not in self.shown and self.events[e].instruction.sensing
        )
        timeline = compile_body(self.program.body, self)
        return Script(
            self.program.path,
            self.program,
            self.events,
            condition_only,
            timeline,
            self.scene,
            self.ctx.scene_override,
        )

    def load_scene(self) -> None:
        caller, override = self.ctx.caller_scene, self.ctx.scene_override
        if isinstance(caller, _SceneFailed):
            self.scene_failed = True
            return
        if caller is not None:
            self.scene = caller
            return
        setting = self.program.scene
        text = override or (setting.text if setting is not None else None)
        if text is None or self.ctx.loader is None:
            return
        # An overriding scene has no place in the script: its problems point at line 1.
        span = setting.span if setting is not None and not override else Span.at(1, 1)
        try:
            self.scene = self.ctx.loader(text, self.origin.parent)
        except SceneNotFoundError as e:
            self.scene_failed = True
            self.error(span, str(e))
        except ValueError as e:
            self.scene_failed = True
            self.error(span, f"scene '{text}' has a bad world file: {e}")
        except OSError as e:  # a name the file system refuses
            self.scene_failed = True
            self.error(span, f"cannot read scene '{text}': {_reason(e)}")

    def define(self, d: Definition) -> None:
        if d.broken:  # its syntax error is reported already
            self.broken.add(d.event)
            return
        instr = INSTRUCTIONS.get(d.instruction)
        if instr is None:
            valid = list(INSTRUCTIONS)
            hint = _hint(d.instruction, valid) or _choices(valid)
            self.error(d.instruction_span, f"unknown instruction '{d.instruction}'{hint}")
            self.broken.add(d.event)
            return
        bound, errors = bind(instr, d, limit=MAX_PROBLEMS - self.seen)
        errors = errors or robot_errors(d, bound, self.scene.robot if self.scene else None)
        for span, message in errors:
            self.error(span, f"event '{d.event}': {message}")
        if errors:
            self.broken.add(d.event)
            return
        args = instr.build(Values(bound.args))
        problem = args.problem()
        if problem is not None:
            self.error(d.instruction_span, f"event '{d.event}': {problem}")
            self.broken.add(d.event)
            return
        if self.scene is not None and not self.scene_names(d.event, instr, bound.args, bound.spans):
            self.broken.add(d.event)
            return
        self.events[d.event] = EventDef(d.event, instr, args, args.effectors(self.scene), d)

    def scene_names(
        self, event: str, instr: Instruction, args: Mapping[str, object], spans: Mapping[str, Span]
    ) -> bool:
        assert self.scene is not None
        ok = True
        specs = instr.verbs.get(str(args.get("verb")), ()) + instr.params
        for spec in specs:
            value = args.get(spec.name)
            if not isinstance(spec.type, Name | Names) or value is None or spec.name not in spans:
                continue
            if spec.name == "save" or spec.type.kind == "set":
                continue  # limp save= names a new pose; point sets are the script's own
            known = self.known(spec.type)
            names = value if isinstance(value, tuple) else (value,)
            for name in (str(n) for n in names if n not in known):
                ok = False
                self.error(spans[spec.name], self.unknown(event, spec.type, name, known))
        return ok

    def known(self, kind: Name | Names) -> list[str]:
        """The scene's names that a parameter of this type may take."""
        assert self.scene is not None
        if isinstance(kind, Name) and kind.anchored:
            return sorted(self.scene.anchored)
        names = {
            "pose": self.scene.poses,
            "location": self.scene.locations,
            "program": self.scene.programs,
            "object": self.scene.objects,
        }
        return list(names[kind.kind])

    def unknown(self, event: str, kind: Name | Names, name: str, known: list[str]) -> str:
        assert self.scene is not None
        if isinstance(kind, Name) and kind.anchored and name in self.scene.locations:
            return (
                f"event '{event}': location '{name}' is not relative to an object (those "
                f"relative to one in scene '{self.scene.name}': {', '.join(known) or 'none'})"
            )
        return (
            f"event '{event}': unknown {kind.kind} '{name}' in scene '{self.scene.name}'"
            f"{self.written_for()}{_hint(name, known)}{_choices(known)}"
        )

    def written_for(self) -> str:
        """For a called script written for another scene: why its names are looked up here."""
        own, caller = self.program.scene, self.scene
        if caller is None or own is None or Path(own.text).stem == caller.name:
            return ""
        if self.ctx.scene_override is not None:
            return f" (--scene replaces this script's own '@scene {own.text}')"
        if isinstance(self.ctx.caller_scene, SceneNames):
            return (
                f", the caller's scene (this script's own '@scene {own.text}' applies only "
                "when it runs by itself)"
            )
        return ""

    def event(self, line: ExecLine) -> EventDef | None:
        event = self.events.get(line.event)
        if event is None and line.event not in self.broken:
            valid = list(self.events)
            hint = _hint(line.event, valid)
            define = f"define it with '% {line.event} INSTRUCTION ...'"
            self.error(
                line.event_span,
                f"unknown event '{line.event}'"
                + (f"{hint} (or {define})" if hint else f": {define}"),
            )
        return event

    def watched(self, line: ExecLine) -> Contact | None:
        event = self.events[line.event]
        instr = event.instruction
        if event.effectors or not instr.sensing:
            what = ", ".join(e for e in EFFECTORS if e in event.effectors) or "an effector"
            self.error(
                line.span_of(*line.watches[0]),
                f"event '{line.event}' cannot be watched: '~' marks a sensing event, and "
                f"'{line.event}' ({instr.name}) commands {what}",
            )
            return None
        contact = event.args.contact()
        if contact is None:
            self.error(
                line.span_of(*line.watches[0]),
                f"event '{line.event}' ({instr.name}) cannot be watched: only "
                f"{', '.join(WATCHABLE[:-1])} and {WATCHABLE[-1]} can, because only a contact "
                "condition holds or not at each moment",
            )
        return contact

    def condition(self, cond: Condition | None) -> None:
        if cond is None or cond.event in self.broken:
            return
        event = self.events.get(cond.event)
        if event is None:
            valid = list(self.events)
            self.error(
                cond.span,
                f"condition event '{cond.event}' is never defined{_hint(cond.event, valid)}",
            )
        elif cond.event not in self.shown and not event.instruction.sensing:
            self.error(
                cond.span,
                f"condition-only event '{cond.event}' must be a sensing instruction "
                f"(get_*, *_contact, record_contact, fit_*), not {event.instruction.name}; "
                "or run it in a diagram before testing it",
            )

    def call(self, stmt: Call) -> Script | None:
        try:
            target = (self.origin.parent / stmt.target).resolve()
            found = target.is_file()
        except (OSError, ValueError) as e:  # a name the file system refuses
            self.error(stmt.span, f"cannot read called script '{stmt.target}': {_reason(e)}")
            return None
        if not found:
            here = Path(self.program.path).parent
            self.error(stmt.span, f"cannot find called script '{stmt.target}' (looked in {here})")
            return None
        key = str(target)
        if key in self.ctx.stack:
            chain = " -> ".join(Path(p).name for p in (*self.ctx.stack, key))
            self.error(stmt.span, f"call cycle: {chain}")
            return None
        inherited: _CallerScene = _SCENE_FAILED if self.scene_failed else self.scene
        # A script called many times (or from many callers) is checked once per scene and
        # level: a chain of scripts that each call the next twice stays linear.
        memo = (key, id(inherited), stmt.depth)
        if memo not in self.ctx.callees:
            before = len(self.ctx.diags)
            display = str(Path(self.program.path).parent / stmt.target)
            ctx = replace(self.ctx, caller_scene=inherited, depth=stmt.depth)
            callee: Script | None = None
            try:
                callee = _check_file(target, display, ctx)
            except OSError as e:
                self.error(stmt.span, f"cannot read called script '{stmt.target}': {_reason(e)}")
            ok = callee is not None and len(self.ctx.diags) == before
            self.ctx.callees[memo] = (callee, inherited) if ok else (None, inherited)
        return self.ctx.callees[memo][0]


def _reason(e: OSError | ValueError) -> str:
    if isinstance(e, OSError) and e.strerror:
        return e.strerror
    return str(e)


def _check(text: str, path: str, origin: Path, ctx: _Context) -> Script:
    """Parse and check ``text``, appending its problems to ``ctx.diags``.

    ``path`` is how messages name the file; ``origin`` is the real file that ``@call``
    and ``@scene`` paths are relative to.
    """
    program, syntax = parse_partial(text, path, depth=ctx.depth)
    ctx.diags.extend(syntax)
    checker = _Checker(program, text, origin, ctx.entering(origin))
    with suppress(TooManyProblems):  # at the file's MAX_PROBLEMS-th problem, as compilers do
        return checker.run(len(syntax))  # (a parser that stopped there left its Cutoff too)
    return Script(program.path, program, {}, frozenset(), (), None, ctx.scene_override)


def _check_file(path: Path, display: str, ctx: _Context) -> Script:
    raw = path.read_bytes()
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as e:  # say where, then check the rest as well as it reads
        text = raw.decode("utf-8", errors="replace")
        start = raw.rfind(b"\n", 0, e.start) + 1
        line = raw.count(b"\n", 0, e.start) + 1
        col = len(raw[start : e.start].decode("utf-8", errors="replace")) + 1
        source = text.split("\n")[line - 1]
        message = f"not UTF-8 text (byte 0x{raw[e.start]:02X}); dial scripts are UTF-8"
        ctx.diags.append(Diagnostic(display, Span.at(line, col), message, source))
    return _check(text, display, path, ctx)


@contextmanager
def _no_gc() -> Iterator[None]:
    """Pause the cyclic garbage collector: a script's tree holds no cycles, and on a large
    script its collections would make the check's cost grow faster than its size.

    Afterwards, freezing and at once unfreezing moves what the check made into the oldest
    generation without a pass over it (a young-generation pass over a large script's tree
    costs a fifth of its check); it stays collectable there, as any long-lived data."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if gc.get_freeze_count() == 0:  # else unfreezing frees what was frozen (dial's start)
            gc.freeze()
            gc.unfreeze()
        if enabled:
            gc.enable()


def _finish(script: Script, ctx: _Context) -> Script:
    if ctx.diags:
        raise ScriptError(ctx.diags)
    return script


def check_text(
    text: str, path: str, *, loader: SceneLoader | None = None, scene: str | None = None
) -> Script:
    """Parse and check ``text``; raise :class:`ScriptError` listing every problem.

    ``path`` names the file in messages, and ``@call`` and ``@scene`` paths are relative
    to it. ``loader`` looks up the names of ``@scene`` (without one, no names are checked).
    ``scene`` (a path or a bundled scene name) replaces the script's ``@scene``, and that
    of every script it calls.
    """
    ctx = _Context(loader, scene)
    with _no_gc():
        return _finish(_check(text, path, Path(path), ctx), ctx)


def load(
    path: str | Path,
    *,
    scene: str | None = None,
    loader: SceneLoader | None = None,
    display: str | None = None,
) -> Script:
    """Read, parse and check a script file; raise :class:`ScriptError` listing every problem.

    ``display`` is how messages name the file (default: ``path``); ``scene`` and
    ``loader`` are as for :func:`check_text`.
    """
    ctx = _Context(loader, scene)
    with _no_gc():
        return _finish(_check_file(Path(path), display or str(path), ctx), ctx)
