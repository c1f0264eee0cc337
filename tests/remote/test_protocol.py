"""The protocol codec, link specs and token files, without a server."""

from __future__ import annotations

import json
import os
import stat

import pytest

from dial.errors import DialError, OptionError
from dial.remote.link import LinkSpec, parse_link
from dial.remote.protocol import (
    MAX_MESSAGE,
    TO_OPERATOR,
    TO_ROBOT,
    VERSION,
    ProtocolError,
    decode,
    encode,
)
from dial.remote.tokens import ensure_token, read_token


def _code(raw: str | bytes) -> str:
    with pytest.raises(ProtocolError) as e:
        decode(raw, TO_ROBOT)
    return e.value.code


def test_good_messages_round_trip() -> None:
    msg = decode(encode("block", seq=3, id="c3", tick=9, after=2, script="a", block={}), TO_ROBOT)
    assert (msg.type, msg.integer("seq"), msg.text("id"), msg.integer("tick")) == (
        "block",
        3,
        "c3",
        9,
    )
    ack = decode(encode("ack", seq=3, id="c3"), TO_OPERATOR)
    assert ack.type == "ack"


@pytest.mark.parametrize(
    ("raw", "code"),
    [
        ("{not json", "malformed"),
        ("[1, 2]", "malformed"),
        ('{"v": 1, "type": "status", "x": NaN}', "malformed"),
        (b'{"v": 1}', "malformed"),
        ('{"v": 2, "type": "status"}', "version"),
        ('{"type": "status"}', "version"),
        ('{"v": true, "type": "status"}', "version"),
        ('{"v": 1, "type": "launch"}', "unknown_type"),
        ('{"v": 1, "type": "ack", "seq": 1, "id": "a"}', "unknown_type"),  # the robot's own
        ('{"v": 1, "type": "hello", "role": "operator"}', "invalid"),
        ('{"v": 1, "type": "hello", "token": 5, "role": "operator"}', "invalid"),
        ('{"v": 1, "type": "end", "seq": true, "id": "a", "tick": 1, "after": 0}', "invalid"),
        ('{"v": 1, "type": "end", "seq": 1e400, "id": "a", "tick": 1, "after": 0}', "invalid"),
    ],
)
def test_bad_messages_name_their_error(raw: str | bytes, code: str) -> None:
    assert _code(raw) == code


def test_an_oversized_message_is_refused_before_it_is_parsed() -> None:
    big = json.dumps({"v": VERSION, "type": "status", "pad": "x" * MAX_MESSAGE})
    assert _code(big) == "too_large"


def test_link_specs() -> None:
    spec = parse_link("delay=1s jitter=100ms bandwidth=2400bps cut=5:3 blackhole=20 seed=4")
    assert spec == LinkSpec(1.0, 0.1, 2400.0, (5.0, 3.0), 20.0, 4)
    assert parse_link("") == LinkSpec()
    assert parse_link("bandwidth=10kbps").bandwidth == 10000.0
    for bad in ("delay=fast", "delay", "cut=5", "seed=-1", "colour=red", "delay=1s delay=2s"):
        with pytest.raises(OptionError, match="--link"):
            parse_link(bad)


def test_token_files_are_private(tmp_path: object) -> None:
    from pathlib import Path

    path = Path(str(tmp_path)) / "sub" / "token"
    token, created = ensure_token(path)
    assert created and len(token) > 30
    assert stat.S_IMODE(path.stat().st_mode) == 0o600
    assert ensure_token(path) == (token, False)
    os.chmod(path, 0o644)
    with pytest.raises(DialError, match="0600"):
        read_token(path)
    with pytest.raises(DialError, match="no token file"):
        read_token(path.with_name("missing"))


def test_nothing_is_unpickled_nor_evaluated() -> None:
    """JSON is the only encoding: no module of the remote side imports pickle, marshal or
    shelve, or calls eval or exec."""
    import ast
    from pathlib import Path

    from dial.remote import protocol

    paths = sorted(Path(protocol.__file__).parent.glob("*.py"))
    assert len(paths) > 10
    for path in paths:
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import | ast.ImportFrom):
                names = [a.name for a in node.names] + [getattr(node, "module", None) or ""]
                assert not {"pickle", "marshal", "shelve", "dill"} & set(names), path
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
                assert node.func.id not in ("eval", "exec"), path
