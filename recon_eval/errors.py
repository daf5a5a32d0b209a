"""The exception types for bad input; the CLI turns them into exit code 2 without a traceback."""
from __future__ import annotations


class InputError(ValueError):
    """Input of the wrong shape, type or content (the message names what was expected)."""


class NotApplicable(InputError):
    """The dataset lacks the truth the caller needs (no cross-view truth for a pair, no board, no
    stereo rig, no match sets...): the CLI reports it as bad input, a runner's method is skipped."""
