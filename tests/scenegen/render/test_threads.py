"""Dr.Jit's thread pool size (scenegen.render.threads): set and read back; a bad count refused."""
from __future__ import annotations

import os

import pytest

from scenegen.render.threads import render_threads, set_render_threads


def test_a_count_below_one_is_refused():
    with pytest.raises(ValueError, match="at least 1, got 0"):
        set_render_threads(0)


@pytest.mark.render
def test_set_and_read_back():
    set_render_threads(1)
    try:
        assert render_threads() == 1
    finally:
        set_render_threads(os.cpu_count() or 1)  # Dr.Jit's default: one per core
    assert render_threads() == (os.cpu_count() or 1)
