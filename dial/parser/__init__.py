"""The DIAL script language: parse, check, compile, show and format.

This package imports neither MuJoCo nor trio.
"""

from dial.parser.check import check_text, load
from dial.parser.parse import parse, parse_partial
from dial.parser.script import EventDef, Run, Script, Step, TBlock, TCall, TIf, TRepeat
from dial.parser.timeline import expand

__all__ = [
    "EventDef",
    "Run",
    "Script",
    "Step",
    "TBlock",
    "TCall",
    "TIf",
    "TRepeat",
    "check_text",
    "expand",
    "load",
    "parse",
    "parse_partial",
]
