"""Check a parsed program against the instruction catalogue and compile its timeline.

Everything here is known without the simulator. Checks that need a scene's
world file (unknown pose, location or program) go through a
:data:`~dial.instructions.scene_names.SceneLoader`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from difflib import get_close_matches
from pathlib import Path
from typing import Any

from dial.errors import Diagnostic, ScriptError, Span
from dial.instructions.catalogue import INSTRUCTIONS, Instruction
from dial.instructions.scene_names import SceneLoader, SceneNames, SceneNotFoundError
from dial.instructions.types import FINGERS, Name
from dial.parser.ast import Block, Call, Condition, Definition, If, Program, Repeat, Statement
from dial.parser.bind import bind
from dial.parser.parse import parse_partial
from dial.parser.timeline import Run, Step, TBlock, TCall, TIf, TRepeat


@dataclass(frozen=True)
class EventDef:
    """A defined event bound to its instruction."""

    name: str
    instruction: Instruction
    args: Mapping[str, Any]  # bound values, SI units
    effectors: frozenset[str]
    definition: Definition


@dataclass(frozen=True)
class Script:
    """A checked script: its program, bound events and compiled timeline."""

    path: str
    program: Program
    events: Mapping[str, EventDef]
    condition_only: frozenset[str]
    timeline: tuple[Step, ...]
    scene: SceneNames | None
    # ``dial run --scene``: the scene that replaces ``@scene`` here and in every called script
    # (an absolute path or a bundled name), or None to use ``@scene``.
    scene_override: str | None = None

    @property
    def tick(self) -> float | None:
        return self.program.tick


def _hint(name: str, valid: list[str]) -> str:
    close = get_close_matches(name, valid, n=3)
    return f"; did you mean {' or '.join(repr(c) for c in close)}?" if close else ""


def _choices(valid: list[str]) -> str:
    return f" (valid: {', '.join(sorted(valid))})" if valid else " (none are defined)"


class _SceneFailed:
    """The caller's scene did not load (its error is reported): check no names in callees."""


SCENE_FAILED = _SceneFailed()
CallerScene = SceneNames | _SceneFailed | None


class _Checker:
    def __init__(
        self,
        program: Program,
        source: str,
        loader: SceneLoader | None,
        stack: tuple[str, ...],
        diags: list[Diagnostic],
        origin: Path,
        scene_override: str | None,
        caller_scene: CallerScene = None,
    ) -> None:
        self.program = program
        self.scene_override = scene_override
        self.caller_scene = caller_scene  # a called script runs in its caller's scene
        self.origin = origin  # the real file, for resolving @call and @scene paths
        self.lines = source.split("\n")
        self.loader = loader
        self.stack = stack
        self.diags = diags
        self.events: dict[str, EventDef] = {}
        self.broken: set[str] = set()  # defined, but the definition has errors
        self.scene: SceneNames | None = None
        self.scene_failed = False

    def error(self, span: Span, message: str, path: str | None = None) -> None:
        text = self.lines[span.line - 1] if 0 < span.line <= len(self.lines) else ""
        self.diags.append(Diagnostic(path or self.program.path, span, message, text))

    def run(self) -> Script:
        self.load_scene()
        for d in self.program.definitions:
            self.define(d)
        shown = self.diagram_events(self.program.body)
        condition_only = frozenset(
            e for e in self.events if e not in shown and self.events[e].instruction.sensing
        )
        timeline = self.compile(self.program.body, shown)
        return Script(
            self.program.path,
            self.program,
            self.events,
            condition_only,
            timeline,
            self.scene,
            self.scene_override,
        )

    def load_scene(self) -> None:
        if isinstance(self.caller_scene, _SceneFailed):
            self.scene_failed = True
            return
        if self.caller_scene is not None:
            self.scene = self.caller_scene
            return
        setting = self.program.scene
        text = self.scene_override or (setting.text if setting is not None else None)
        if text is None or self.loader is None:
            return
        # An overriding scene has no place in the script: its problems point at line 1.
        span = setting.span if setting is not None and not self.scene_override else Span.at(1, 1)
        try:
            self.scene = self.loader(text, self.origin.parent)
        except SceneNotFoundError as e:
            self.scene_failed = True
            self.error(span, str(e))
        except ValueError as e:
            self.scene_failed = True
            self.error(span, f"scene '{text}' has a bad world file: {e}")

    def define(self, d: Definition) -> None:
        if d.broken:  # its syntax error is reported already
            self.broken.add(d.event)
            return
        instr = INSTRUCTIONS.get(d.instruction)
        if instr is None:
            valid = list(INSTRUCTIONS)
            self.error(
                d.instruction_span,
                f"unknown instruction '{d.instruction}'"
                + (_hint(d.instruction, valid) or _choices(valid)),
            )
            self.broken.add(d.event)
            return
        bound, errors = bind(instr, d)
        for span, message in errors:
            self.error(span, f"event '{d.event}': {message}")
        if errors:
            self.broken.add(d.event)
            return
        if self.scene is not None and not self.scene_names(d.event, instr, bound.args, bound.spans):
            self.broken.add(d.event)
            return
        effectors = instr.effectors(bound.args, self.scene)
        self.events[d.event] = EventDef(d.event, instr, bound.args, effectors, d)

    def scene_names(
        self, event: str, instr: Instruction, args: Mapping[str, object], spans: Mapping[str, Span]
    ) -> bool:
        assert self.scene is not None
        ok = True
        specs = instr.verbs.get(str(args.get("verb")), ()) + instr.params
        for spec in specs:
            value = args.get(spec.name)
            if not isinstance(spec.type, Name) or value is None or spec.name not in spans:
                continue
            kind = spec.type.kind
            known: list[str]
            if kind == "pose":
                known = list(self.scene.poses)
            elif kind == "location":
                known = list(self.scene.locations)
            elif kind == "program":
                known = list(self.scene.programs)
            else:
                continue
            if spec.name == "save" or value in known:
                continue  # limp save= names a new pose
            ok = False
            self.error(
                spans[spec.name],
                f"event '{event}': unknown {kind} '{value}' in scene '{self.scene.name}'"
                f"{self.written_for()}{_hint(str(value), known)}{_choices(known)}",
            )
        return ok

    def written_for(self) -> str:
        """For a called script written for another scene: why its names are looked up here."""
        own, caller = self.program.scene, self.scene
        if caller is None or own is None or Path(own.text).stem == caller.name:
            return ""
        if self.scene_override is not None:
            return f" (--scene replaces this script's own '@scene {own.text}')"
        if isinstance(self.caller_scene, SceneNames):
            return (
                f", the caller's scene (this script's own '@scene {own.text}' applies only "
                "when it runs by itself)"
            )
        return ""

    def diagram_events(self, body: tuple[Statement, ...]) -> set[str]:
        names: set[str] = set()
        for stmt in body:
            if isinstance(stmt, Block):
                names.update(line.event for line in stmt.lines)
            elif isinstance(stmt, Repeat):
                names |= self.diagram_events(stmt.body)
            elif isinstance(stmt, If):
                names |= self.diagram_events(stmt.then) | self.diagram_events(stmt.orelse)
        return names

    def condition(self, cond: Condition | None, shown: set[str]) -> None:
        if cond is None or cond.event in self.broken:
            return
        event = self.events.get(cond.event)
        if event is None:
            valid = list(self.events)
            self.error(
                cond.span,
                f"condition event '{cond.event}' is never defined{_hint(cond.event, valid)}",
            )
        elif cond.event not in shown and not event.instruction.sensing:
            self.error(
                cond.span,
                f"condition-only event '{cond.event}' must be a sensing instruction "
                f"(get_*, *_contact, record_contact, fit_*), not {event.instruction.name}; "
                "or run it in a diagram before testing it",
            )

    def compile(self, body: tuple[Statement, ...], shown: set[str]) -> tuple[Step, ...]:
        steps: list[Step] = []
        for stmt in body:
            if isinstance(stmt, Block):
                steps.append(self.block(stmt))
            elif isinstance(stmt, Repeat):
                self.condition(stmt.condition, shown)
                inner = self.compile(stmt.body, shown)
                steps.append(TRepeat(stmt.kind, stmt.count, stmt.condition, inner, stmt.line))
            elif isinstance(stmt, If):
                self.condition(stmt.condition, shown)
                then, orelse = self.compile(stmt.then, shown), self.compile(stmt.orelse, shown)
                steps.append(TIf(stmt.condition, then, orelse, stmt.line))
            else:
                callee = self.call(stmt)
                if callee is not None:
                    steps.append(TCall(stmt.target, callee, stmt.line))
        return tuple(steps)

    def block(self, block: Block) -> TBlock:
        runs: list[Run] = []
        for line in block.lines:
            event = self.events.get(line.event)
            if event is None:
                if line.event not in self.broken:
                    valid = list(self.events)
                    hint = _hint(line.event, valid)
                    define = f"define it with '% {line.event} INSTRUCTION ...'"
                    self.error(
                        line.event_span,
                        f"unknown event '{line.event}'"
                        + (f"{hint} (or {define})" if hint else f": {define}"),
                    )
                continue
            for mark in line.runs:
                runs.append(
                    Run(
                        line.event,
                        line.line,
                        mark.start,
                        mark.exec_end,
                        mark.hold_end,
                        event.effectors,
                        mark.span,
                    )
                )
        runs.sort(key=lambda r: (r.start, r.line))
        self.conflicts(runs)
        return TBlock(block.line, block.length, tuple(runs))

    def conflicts(self, runs: list[Run]) -> None:
        reported: set[tuple[int, int]] = set()
        for i, a in enumerate(runs):
            for b in runs[i + 1 :]:
                if b.start > a.hold_end:
                    break  # sorted by start: no later run overlaps a
                first, last = max(a.start, b.start), min(a.hold_end, b.hold_end)
                key = (a.line, b.line)
                if first > last or key in reported:
                    continue
                shared = a.effectors & b.effectors
                ticks = f"tick {first}" if first == last else f"ticks {first}-{last}"
                if a.event == b.event and a.line != b.line:
                    reported.add(key)
                    self.error(
                        b.span,
                        f"event '{b.event}' (line {b.line}) overlaps its own run on line "
                        f"{a.line} in {ticks}",
                    )
                elif shared:
                    reported.add(key)
                    names = ", ".join(e for e in ("arm", *FINGERS) if e in shared)
                    self.error(
                        b.span,
                        f"effector conflict: '{b.event}' (line {b.line}) and '{a.event}' "
                        f"(line {a.line}) both command {names} in {ticks}",
                    )

    def call(self, stmt: Call) -> Script | None:
        target = (self.origin.parent / stmt.target).resolve()
        if not target.is_file():
            here = Path(self.program.path).parent
            self.error(stmt.span, f"cannot find called script '{stmt.target}' (looked in {here})")
            return None
        key = str(target)
        if key in self.stack:
            chain = " -> ".join(Path(p).name for p in (*self.stack, key))
            self.error(stmt.span, f"call cycle: {chain}")
            return None
        before = len(self.diags)
        display = str(Path(self.program.path).parent / stmt.target)
        inherited: CallerScene = SCENE_FAILED if self.scene_failed else self.scene
        callee = check_file(
            target, self.loader, self.stack, self.diags, display, self.scene_override, inherited
        )
        if callee is None or len(self.diags) > before:
            return None
        return callee


def check_text(
    text: str,
    path: str,
    loader: SceneLoader | None = None,
    stack: tuple[str, ...] = (),
    diags: list[Diagnostic] | None = None,
    origin: Path | None = None,
    scene: str | None = None,
    caller_scene: CallerScene = None,
) -> Script | None:
    """Parse and check ``text``; append problems to ``diags`` (raise if ``diags`` is None).

    ``path`` is how messages name the file; ``origin`` is the real file that
    ``@call`` and ``@scene`` paths are relative to (default: ``path``). ``scene``, if
    given, replaces the ``@scene`` of this script and of every script it calls.
    ``caller_scene`` is the scene of the script that calls this one, if any: a called
    script's names are checked against it, whatever its own ``@scene`` says
    (:data:`SCENE_FAILED`: the caller's scene did not load, so no names are checked).
    """
    own = diags is None
    sink: list[Diagnostic] = [] if diags is None else diags
    program, syntax = parse_partial(text, path)
    sink.extend(syntax)
    origin = Path(path) if origin is None else origin
    resolved = str(origin.resolve())
    script = _Checker(
        program, text, loader, (*stack, resolved), sink, origin, scene, caller_scene
    ).run()
    if own and sink:
        raise ScriptError(sink)
    return script


def check_file(
    path: Path,
    loader: SceneLoader | None = None,
    stack: tuple[str, ...] = (),
    diags: list[Diagnostic] | None = None,
    display: str | None = None,
    scene: str | None = None,
    caller_scene: CallerScene = None,
) -> Script | None:
    """Read, parse and check the script at ``path`` (``display`` is how errors name it)."""
    text = Path(path).read_text(encoding="utf-8", errors="replace")
    return check_text(
        text, display or str(path), loader, stack, diags, Path(path), scene, caller_scene
    )


def load(
    path: str | Path,
    loader: SceneLoader | None = None,
    display: str | None = None,
    scene: str | None = None,
) -> Script:
    """Parse and check a script file; raise :class:`ScriptError` listing every problem.

    ``scene`` (a path or a bundled scene name) replaces the script's ``@scene``, and that of
    every script it calls.
    """
    diags: list[Diagnostic] = []
    script = check_file(Path(path), loader, (), diags, display, scene)
    if diags:
        raise ScriptError(diags)
    assert script is not None
    return script
