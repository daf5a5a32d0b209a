"""The one exception type for bad input; the CLI turns it into exit code 2 without a traceback."""
from __future__ import annotations


class InputError(ValueError):
    """Input of the wrong shape, type or content (the message names what was expected)."""
