"""Temporary re-export of the compiled program types (the parser split replaces this)."""

from dial.parser.check import EventDef, Script
from dial.parser.timeline import (
    Run,
    Step,
    TAbort,
    TBlock,
    TCall,
    TIf,
    TOn,
    TRepeat,
    TResume,
    TRetry,
    Watch,
)

__all__ = [
    "EventDef",
    "Run",
    "Script",
    "Step",
    "TAbort",
    "TBlock",
    "TCall",
    "TIf",
    "TOn",
    "TRepeat",
    "TResume",
    "TRetry",
    "Watch",
]
