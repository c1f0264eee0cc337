"""The shared secret of a robot and its operators: a token in a file of mode 0600.

``dial serve --token-file F`` reads the token from F, or writes a new one there when F does
not exist; without ``--token-file`` it uses a file beside its log, or in the user's state
folder. ``dial run --remote`` reads the same file.
"""

from __future__ import annotations

import hmac
import os
import secrets
import stat
from pathlib import Path

from dial.errors import DialError

TOKEN_BYTES = 32


def default_token_file(log: str | None = None) -> Path:
    """Beside the log (``F.jsonl`` -> ``F.token``), else ``$XDG_STATE_HOME/dial/token``."""
    if log is not None:
        return Path(log).with_suffix(".token")
    state = os.environ.get("XDG_STATE_HOME") or str(Path.home() / ".local" / "state")
    return Path(state) / "dial" / "token"


def read_token(path: Path) -> str:
    """The token in ``path``; a one-line error if it is missing, empty or open to others."""
    try:
        mode = path.stat().st_mode
        text = path.read_text(encoding="utf-8").strip()
    except FileNotFoundError:
        raise DialError(f"no token file '{path}' (dial serve writes one)") from None
    except (OSError, UnicodeDecodeError) as e:
        raise DialError(f"cannot read the token file '{path}': {e}") from None
    if mode & (stat.S_IRWXG | stat.S_IRWXO):
        raise DialError(
            f"the token file '{path}' is open to other users (mode {mode & 0o777:o}): make it 0600"
        )
    if not text or not text.isascii() or any(c.isspace() for c in text):
        raise DialError(f"the token file '{path}' holds no token")
    return text


def ensure_token(path: Path) -> tuple[str, bool]:
    """The token in ``path``, or a new one written there with mode 0600; (token, created)."""
    if path.exists():
        return read_token(path), False
    token = secrets.token_urlsafe(TOKEN_BYTES)
    try:
        path.parent.mkdir(parents=True, exist_ok=True, mode=0o700)
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    except FileExistsError:  # another process wrote it just now: take that one
        return read_token(path), False
    except OSError as e:
        raise DialError(f"cannot write the token file '{path}': {e.strerror or e}") from None
    with os.fdopen(fd, "w", encoding="utf-8") as f:
        f.write(token + "\n")
    return token, True


def same_token(given: str, expected: str) -> bool:
    """Compare in constant time."""
    return hmac.compare_digest(given.encode("utf-8"), expected.encode("utf-8"))
