"""dial: run DIAL-style tick-based timeline scripts on a simulated Utah/MIT hand on a PUMA 560."""

from dial.errors import Diagnostic, DialError, ScriptError, Span

__version__ = "0.1.0"
__all__ = ["Diagnostic", "DialError", "ScriptError", "Span", "__version__"]
