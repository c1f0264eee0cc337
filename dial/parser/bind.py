"""Bind a definition's written parameters to its instruction's schema."""

from __future__ import annotations

from dataclasses import dataclass
from difflib import get_close_matches

from dial.errors import Span
from dial.instructions.base import Instruction, ParamSpec
from dial.instructions.types import ParamError
from dial.parser.ast import Definition, Word


@dataclass(frozen=True)
class Bound:
    """Bound arguments (SI values) and the span each came from."""

    args: dict[str, object]
    spans: dict[str, Span]


def _parse(spec: ParamSpec[object], word: Word, errors: list[tuple[Span, str]]) -> object:
    try:
        return spec.type.parse(word.text)
    except ParamError as e:
        errors.append((word.span, f"bad {spec.name}: {e}"))
        return None


def bind(
    instr: Instruction, defn: Definition, limit: int | None = None
) -> tuple[Bound, list[tuple[Span, str]]]:
    """Bind ``defn``'s parameters; return the arguments and any problems (at most ``limit``
    of the ``key=value`` ones: the checker stops at so many)."""
    errors: list[tuple[Span, str]] = []
    bound = Bound({}, {})
    specs = _positional(instr, defn, bound, errors)
    if specs is None:
        return bound, errors
    _keyed(instr, defn, bound, errors, limit)
    args = bound.args
    for spec in specs if instr.verbs else instr.params:
        if spec.name in args:
            continue
        if spec.required:
            how = spec.name if spec.positional or instr.verbs else f"{spec.name}="
            errors.append(
                (
                    defn.instruction_span,
                    f"{instr.name} is missing {how} ({spec.type.expected}); usage: {instr.usage}",
                )
            )
        else:
            args[spec.name] = spec.default
    return bound, errors


def _positional(
    instr: Instruction, defn: Definition, bound: Bound, errors: list[tuple[Span, str]]
) -> tuple[ParamSpec[object], ...] | None:
    """Bind the positional words (after a verb, for verb-style instructions); return the
    specs that apply, or None if the verb is missing or bad."""
    usage = f"usage: {instr.usage}"
    words = [w for p in defn.params if p.key is None for w in p.words]
    specs: tuple[ParamSpec[object], ...]
    if instr.verbs:
        if not words:
            errors.append((defn.instruction_span, f"{instr.name} needs a command; {usage}"))
            return None
        verb = _parse(instr.params[0], words[0], errors)
        if verb is None:
            return None
        bound.args["verb"], bound.spans["verb"] = verb, words[0].span
        specs, words = instr.verbs[str(verb)], words[1:]
    else:
        specs = tuple(p for p in instr.params if p.positional)
    if len(words) > len(specs):
        extra = words[len(specs)].span.to(words[-1].span)
        errors.append((extra, f"too many parameters for {instr.name}; {usage}"))
    elif instr.positional_counts and len(words) not in instr.positional_counts:
        counts = " or ".join(str(n) for n in instr.positional_counts)
        where = words[0].span.to(words[-1].span) if words else defn.instruction_span
        errors.append((where, f"{instr.name} takes {counts} numbers, got {len(words)}; {usage}"))
    for spec, word in zip(specs, words, strict=False):
        bound.args[spec.name], bound.spans[spec.name] = _parse(spec, word, errors), word.span
    return specs


def _keyed(
    instr: Instruction,
    defn: Definition,
    bound: Bound,
    errors: list[tuple[Span, str]],
    limit: int | None,
) -> None:
    """Bind the ``key=value`` parameters, until ``limit`` problems are found."""
    for p in defn.params:
        if p.key is None:
            continue
        if limit is not None and len(errors) >= limit:
            return
        keyed = None if instr.verbs else instr.spec(p.key)
        if keyed is None:
            names = [s.name for s in instr.params if not instr.verbs]
            close = get_close_matches(p.key, names, n=1)
            hint = f"; did you mean '{close[0]}'?" if close else ""
            valid = f" (valid: {', '.join(names)})" if names else ""
            errors.append((p.span, f"unknown parameter '{p.key}' for {instr.name}{hint}{valid}"))
            continue
        if p.key in bound.spans:
            errors.append((p.span, f"parameter '{p.key}' is given twice"))
            continue
        if len(p.words) != 1:
            errors.append((p.span, f"'{p.key}' takes one value: expected {keyed.type.expected}"))
            continue
        bound.args[p.key], bound.spans[p.key] = _parse(keyed, p.words[0], errors), p.words[0].span
