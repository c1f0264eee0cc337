"""Fuzz the checker: mutated scripts through check, show and fmt, in process.

Seeds are the bundled scripts and the golden test scripts. Each input applies one to four
mutations (bytes, lines or tokens) to a seed, then runs it the way ``dial check``,
``dial show`` and ``dial fmt`` do. A ``ScriptError`` (or another ``DialError``) is a
rejection; anything else raised is an internal error, and an input that takes longer than
``--timeout`` seconds (a SIGALRM timer) is a hang. Both must be 0 (issue 15).

    python benchmarks/fuzz_check.py [--inputs 100000] [--seed 1] [--save DIR]

The same seed gives the same inputs. ``tests/test_fuzz.py`` runs a share of it.
"""

from __future__ import annotations

import argparse
import random
import signal
import sys
import time
import traceback
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from types import FrameType

from dial.errors import DialError, ScriptError
from dial.instructions.scene_names import SceneLoader, SceneNames
from dial.parser import check_text, parse
from dial.parser.fmt import format_text
from dial.parser.show import render
from dial.scene import load_scene_names

ROOT = Path(__file__).resolve().parent.parent
SEED_DIRS = (
    ROOT / "scripts",
    ROOT / "tests" / "data" / "valid",
    ROOT / "tests" / "data" / "invalid",
)

# Characters and fragments that the grammar gives a meaning, and some that it must refuse.
CHARS: list[str] = [
    *'#=-~. \t\n%@/*"!_:,0123456789aZx',
    "\r\n",
    "\x00",
    "\x7f",
    "²",
    "٣",
    "é",
    "\u00a0",
]
TOKENS: list[str] = [
    *("@repeat", "@if", "@else", "@end", "@call", "@scene", "@tick", "@on", "@resume"),
    *("@retry", "@retry max 0", '@abort "x"', "@abort", "until", "while", "max", "!"),
    *("#", "#===", "#---", "~~~", "~#", ".", "=", "-", "0x0666_0x0222", "4N", "10deg"),
    *("²", "4²", "1" * 4301, "0x" + "f" * 30, "1e999", "nan", "-0", "999999999999"),
    *("a" * 300 + ".dial", "a\x00.dial", "lib/sub.dial", "../valid/call_sub.dial", "pour"),
    *("finger=index", "finger=thumb", "threshold=1N", "timeout=0s", "fingers=0x0", "y=1"),
    *('"', '""', '"ex to_bulb"', '"drive 3 350"', "/*", "*/", "//", "\t", "\x00"),
]
LINES = [
    "@repeat 1000",
    "@repeat 1000000",
    "@if x\n" * 120 + "x #\n" + "@end\n" * 120,
    "@repeat 2\n" * 60 + "@end\n" * 60,
    "go " + "#" * 500,
    "% t tactile_contact finger=index",
    "t ~~~~",
    "@on t",
    "@on !t",
    "% g get_joints " + "y=1 " * 500,
]


@dataclass
class Tally:
    accepted: int = 0
    rejected: int = 0
    internal: int = 0
    hangs: int = 0
    failures: list[tuple[str, str, str]] = field(default_factory=list)  # kind, seed, text


class Hang(Exception):
    """An input ran past its time limit."""


@contextmanager
def time_limit(seconds: float) -> Iterator[None]:
    def expire(signum: int, frame: FrameType | None) -> None:
        raise Hang

    previous = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


Seed = tuple[Path, str]


def seeds() -> tuple[list[Seed], list[Seed]]:
    """The valid and the invalid seed scripts, with their paths (so that calls resolve)."""
    good: list[Seed] = []
    bad: list[Seed] = []
    for folder in SEED_DIRS:
        for path in sorted(folder.glob("*.dial")):
            pool = bad if folder.name == "invalid" else good
            pool.append((path, path.read_text(encoding="utf-8", errors="replace")))
    return good, bad


def mutate_bytes(rng: random.Random, text: str) -> str:
    i = rng.randrange(len(text) + 1)
    op = rng.randrange(3)
    ch = rng.choice(CHARS)
    if op == 0:
        return text[:i] + ch + text[i:]
    if op == 1:
        return text[:i] + text[i + rng.randint(1, 4) :]
    return text[:i] + ch + text[i + 1 :]


def mutate_lines(rng: random.Random, text: str) -> str:
    lines = text.split("\n")
    i, j = rng.randrange(len(lines)), rng.randrange(len(lines))
    op = rng.randrange(5)
    if op == 0:
        lines.insert(j, lines[i])
    elif op == 1:
        del lines[i]
    elif op == 2:
        lines[i], lines[j] = lines[j], lines[i]
    elif op == 3:
        lines.insert(i, rng.choice(LINES))
    else:
        lines[i : i + 1] = [lines[i]] * rng.randint(2, 50)
    return "\n".join(lines)


def mutate_tokens(rng: random.Random, text: str) -> str:
    words = text.split(" ")
    i = rng.randrange(len(words))
    if rng.random() < 0.5:
        words[i] = rng.choice(TOKENS)
    else:
        words.insert(i, rng.choice(TOKENS))
    return " ".join(words)


MUTATORS: tuple[Callable[[random.Random, str], str], ...] = (
    mutate_bytes,
    mutate_bytes,
    mutate_lines,
    mutate_tokens,
)


def mutant(rng: random.Random, pools: tuple[list[Seed], list[Seed]]) -> Seed:
    """A seed, valid three times in four, mutated one to four times."""
    path, text = rng.choice(pools[0] if rng.random() < 0.75 else pools[1])
    for _ in range(rng.randint(1, 4)):
        text = rng.choice(MUTATORS)(rng, text)
    return path, text


def cached_loader() -> SceneLoader:
    """``load_scene_names``, remembered per (scene, folder): the files do not change."""
    memo: dict[tuple[str, str], SceneNames | Exception] = {}

    def load(scene: str, folder: Path) -> SceneNames:
        key = (scene, str(folder))
        if key not in memo:
            try:
                memo[key] = load_scene_names(scene, folder)
            except (LookupError, ValueError) as e:
                memo[key] = e
        found = memo[key]
        if isinstance(found, Exception):
            raise found
        return found

    return load


def exercise(path: Path, text: str, loader: SceneLoader) -> bool:
    """Check, show and format ``text`` as if it were ``path``; True if it checks."""
    try:
        script = check_text(text, str(path), loader=loader)
    except ScriptError as e:
        e.render()
        accepted = False
    else:
        render(script)
        accepted = True
    try:
        formatted = format_text(text, str(path))
    except ScriptError:
        return accepted
    if parse(formatted, str(path)) != parse(text, str(path)):
        raise AssertionError("fmt changed the program")
    return accepted


def fuzz(inputs: int, seed: int, timeout: float = 2.0) -> Tally:
    rng = random.Random(seed)
    pool = seeds()
    loader = cached_loader()
    tally = Tally()
    for _ in range(inputs):
        path, text = mutant(rng, pool)
        try:
            with time_limit(timeout):
                ok = exercise(path, text, loader)
        except Hang:
            tally.hangs += 1
            tally.failures.append(("hang", path.name, text))
        except DialError:
            tally.rejected += 1  # an error a user can cause, reported as one line
        except Exception:  # an internal error is what this counts
            tally.internal += 1
            tally.failures.append(("internal: " + traceback.format_exc(), path.name, text))
        else:
            tally.accepted += ok
            tally.rejected += not ok
    return tally


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--inputs", type=int, default=100_000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--timeout", type=float, default=2.0, help="seconds before a hang")
    ap.add_argument("--save", type=Path, help="write each failing input to this folder")
    args = ap.parse_args()
    sys.setrecursionlimit(1000)  # the default: a deep input must not pass only here
    start = time.perf_counter()
    tally = fuzz(args.inputs, args.seed, args.timeout)
    seconds = time.perf_counter() - start
    print(f"fuzz_check: {args.inputs} inputs, seed {args.seed}, {seconds:.0f} s")
    print(f"  accepted        {tally.accepted}")
    print(f"  rejected        {tally.rejected}")
    print(f"  internal errors {tally.internal}")
    print(f"  hangs (>{args.timeout:g} s)  {tally.hangs}")
    if args.save is not None:
        args.save.mkdir(parents=True, exist_ok=True)
        for n, (kind, seed_name, text) in enumerate(tally.failures):
            (args.save / f"{n:04d}_{seed_name}").write_text(text, encoding="utf-8")
            (args.save / f"{n:04d}_{seed_name}.why").write_text(kind, encoding="utf-8")
    for kind, seed_name, _ in tally.failures[:5]:
        print(f"\n[{seed_name}] {kind}")
    sys.exit(1 if tally.internal or tally.hangs else 0)


if __name__ == "__main__":
    main()
