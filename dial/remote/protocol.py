"""The remote protocol, version 1: JSON text frames over WebSocket (docs/remote.md).

Every message is one JSON object with ``v`` (the protocol version) and ``type``. Messages
are checked field by field against :data:`FIELDS` before anything acts on them; a message
that fails gets an ``error`` reply with one of :data:`ERRORS` and the connection stays
open. Nothing is unpickled: JSON is the only encoding.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import dataclass

VERSION = 1
MAX_MESSAGE = 1 << 20  # bytes: larger messages are refused ('too_large'), the link stays up
# What the WebSocket layer accepts at all: a larger frame closes the connection (1009).
MAX_FRAME = 16 << 20
DEFAULT_PORT = 8765
CLOSE_S = 0.5  # s a closing handshake may take: a cut or dead peer never answers it

# The error codes of an ``error`` message (docs/remote.md lists what each means).
ERRORS = (
    "malformed",  # not JSON, or not an object
    "too_large",  # over MAX_MESSAGE bytes
    "version",  # ``v`` is not VERSION
    "unknown_type",  # ``type`` is not a message this side receives
    "invalid",  # a field is missing or of the wrong kind
    "token",  # hello without the right token: the connection is closed
    "busy",  # another operator controls the robot: the connection is closed
    "order",  # a command before hello, or a second hello
    "no_session",  # a resume of a session that is over
)

# Field kinds: a Python type, or a tuple of types; "?" after a name marks it optional.
_Kind = type | tuple[type, ...]
_NUM = (int, float)
_COMMAND: dict[str, _Kind] = {"seq": int, "id": str}
_TAGGED: dict[str, _Kind] = {**_COMMAND, "tick": int, "after": int}

# What the server receives (from an operator or an observer).
TO_ROBOT: dict[str, dict[str, _Kind]] = {
    "hello": {"token": str, "role": str, "session?": int, "have?": int, "bandwidth?": _NUM},
    "heartbeat": {},
    "status": {},
    "ping": {"id": str},
    "run": {**_TAGGED, "script": dict, "tick_length": _NUM},
    "open": {**_COMMAND, "script": dict, "tick_length": _NUM},
    "block": {**_TAGGED, "script": str, "block": dict},
    "test": {**_TAGGED, "script": str, "line": int, "condition": str},
    "end": {**_TAGGED, "error?": str},
    "stop": _COMMAND,
}
# What the operator receives.
TO_OPERATOR: dict[str, dict[str, _Kind]] = {
    "welcome": {"session": int, "role": str, "robot": dict, "resumed": bool},
    "status": {"state": str},
    "heartbeat": {"tick": int},
    "pong": {"id": str},
    "ack": {"seq": int, "id": str},
    "telemetry": {"periods": int, "tick": int, "t": _NUM, "tool": list},
    "records": {"n": int, "records": list},
    "result": {"n": int, "seq": int, "id": str, "tick": int},
    "refused": {"n": int, "seq": int, "id": str, "code": str, "message": str},
    "finished": {"n": int, "summary": dict},
    "error": {"code": str, "message": str},
}
COMMANDS = frozenset(t for t, f in TO_ROBOT.items() if "seq" in f)
REPORTS = frozenset(t for t, f in TO_OPERATOR.items() if "n" in f)  # re-sent after a cut


class ProtocolError(Exception):
    """A message that cannot be taken: ``code`` is one of :data:`ERRORS`."""

    def __init__(self, code: str, message: str) -> None:
        super().__init__(message)
        self.code = code


@dataclass(frozen=True)
class Message:
    """A checked message: its type and its fields (JSON values, checked against FIELDS)."""

    type: str
    fields: Mapping[str, object]

    def integer(self, name: str, default: int = 0) -> int:
        value = self.fields.get(name, default)
        assert isinstance(value, int)
        return value

    def number(self, name: str, default: float = 0.0) -> float:
        value = self.fields.get(name, default)
        assert isinstance(value, int | float)
        return float(value)

    def text(self, name: str, default: str = "") -> str:
        value = self.fields.get(name, default)
        assert isinstance(value, str)
        return value

    def obj(self, name: str) -> Mapping[str, object]:
        value = self.fields.get(name, {})
        assert isinstance(value, Mapping)
        return value

    def items(self, name: str) -> list[object]:
        value = self.fields.get(name, [])
        assert isinstance(value, list)
        return value


def encode(type_: str, /, **fields: object) -> str:
    """One message as its JSON text (strict JSON: no NaN)."""
    return json.dumps({"v": VERSION, "type": type_, **fields}, separators=(",", ":"))


def decode(raw: str | bytes, accepted: Mapping[str, Mapping[str, _Kind]]) -> Message:
    """Check one received frame against the message types this side accepts.

    Raises :class:`ProtocolError` naming what is wrong; nothing else is raised.
    """
    size = len(raw if isinstance(raw, bytes) else raw.encode("utf-8", "surrogatepass"))
    if size > MAX_MESSAGE:
        raise ProtocolError("too_large", f"a message of {size} bytes; at most {MAX_MESSAGE}")
    if isinstance(raw, bytes):
        raise ProtocolError("malformed", "a binary frame; messages are JSON text frames")
    try:
        obj = json.loads(raw, parse_constant=_no_constant)
    except (ValueError, RecursionError) as e:
        raise ProtocolError("malformed", f"not JSON: {str(e)[:120]}") from None
    if not isinstance(obj, dict):
        raise ProtocolError("malformed", "a message is a JSON object")
    version = obj.get("v")
    if version != VERSION or isinstance(version, bool):
        raise ProtocolError("version", f"protocol version {version!r}; this side speaks {VERSION}")
    kind = obj.get("type")
    if not isinstance(kind, str) or kind not in accepted:
        valid = ", ".join(sorted(accepted))
        raise ProtocolError("unknown_type", f"unknown message type {kind!r}; expected {valid}")
    spec = accepted[kind]
    fields = {k: v for k, v in obj.items() if k not in ("v", "type")}
    for key, want in spec.items():
        name = key.rstrip("?")
        if name not in fields:
            if key.endswith("?"):
                continue
            raise ProtocolError("invalid", f"'{kind}' needs the field '{name}'")
        _check_kind(kind, name, fields[name], want)
    return Message(kind, fields)


def _no_constant(name: str) -> None:
    raise ValueError(f"{name} is not JSON")


def _check_kind(kind: str, name: str, value: object, want: _Kind) -> None:
    wanted = want if isinstance(want, tuple) else (want,)
    if bool in wanted:
        ok = isinstance(value, bool)
    else:
        ok = isinstance(value, wanted) and not isinstance(value, bool)
    if isinstance(value, float) and not math.isfinite(value):
        ok = False
    if not ok:
        names = " or ".join(_KIND_NAMES.get(w, w.__name__) for w in wanted)
        raise ProtocolError("invalid", f"'{kind}': '{name}' must be {names}")
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) > 2**53:
        raise ProtocolError("invalid", f"'{kind}': '{name}' is out of range")


_KIND_NAMES = {int: "an integer", float: "a number", str: "a string", dict: "an object"}
_KIND_NAMES.update({list: "a list", bool: "true or false"})


def error(code: str, message: str) -> str:
    """An ``error`` message."""
    assert code in ERRORS, code
    return encode("error", code=code, message=message)
