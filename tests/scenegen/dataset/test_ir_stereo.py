"""The active IR stereo invalid mask (scenegen.dataset.ir_stereo): its bits from their stated
rules, its PNG round trip and refusals, and the depth range's spec field (read, round trip at its
default and set, a one-line error for min >= max)."""
from __future__ import annotations

import numpy as np
import pytest

from scenegen.dataset.codecs.png import encode_png
from scenegen.dataset.crossview import NO_SURFACE as STATE_NONE, OCCLUDED as STATE_OCC, OUT_OF_FRAME, VISIBLE
from scenegen.dataset.ir_stereo import (NO_SURFACE, OCCLUDED, OUT_OF_RANGE, SHADOW, decode_invalid,
                                        encode_invalid, invalid_mask)
from scenegen.errors import SpecError
from scenegen.spec import parse_spec, spec_sha256, to_yaml

SPEC = """
cameras: {c: {model: pinhole, size: [8, 6], fx: 8, fy: 8}}
objects: [{name: p, shape: {type: plane, size: [1, 1]}}]
views: [{camera: c, look_at: [{eye: [0, -1, 1], target: [0, 0, 0]}]}]
crossview: {pairs: none, RANGE}
"""


def test_each_pixel_gets_the_bits_of_its_reasons():
    z = np.array([np.nan, 0.1, 0.5, 0.5, 0.5, 2.0, 1.0, np.inf])
    lit = np.array([False, True, False, True, True, True, False, True])
    state = np.array([STATE_NONE, VISIBLE, VISIBLE, STATE_OCC, OUT_OF_FRAME, VISIBLE, STATE_OCC, VISIBLE])
    got = invalid_mask(z, lit, state, (0.2, 1.0))
    assert got.dtype == np.uint8
    assert got.tolist() == [NO_SURFACE, OUT_OF_RANGE, SHADOW, OCCLUDED, OCCLUDED, OUT_OF_RANGE,
                            SHADOW | OCCLUDED, NO_SURFACE]  # 1.0 == max is in range


def test_the_mask_round_trips_and_a_foreign_png_is_refused():
    m = np.array([[0, 1, 2], [4, 8, 14]], np.uint8)
    assert np.array_equal(decode_invalid(encode_invalid(m)), m)
    with pytest.raises(ValueError, match="bits 1|2|4|8"):
        decode_invalid(encode_png(np.full((2, 3), 16, np.uint8)))


def test_the_depth_range_is_read_round_trips_and_keeps_old_hashes(tmp_path):
    plain = parse_spec(SPEC.replace(", RANGE", ""), file="s.yaml", base_dir=tmp_path)
    assert plain.crossview.ir_depth_range_m == (0.0, 1000.0) and "ir_depth" not in to_yaml(plain)
    s = parse_spec(SPEC.replace("RANGE", "ir_depth_range_m: [0.2, 3]"), file="s.yaml", base_dir=tmp_path)
    assert s.crossview.ir_depth_range_m == (0.2, 3.0)
    assert spec_sha256(parse_spec(to_yaml(s), file="s.yaml", base_dir=tmp_path)) == spec_sha256(s) != spec_sha256(plain)


def test_an_empty_depth_range_is_a_one_line_error_at_its_line(tmp_path):
    with pytest.raises(SpecError) as e:
        parse_spec(SPEC.replace("RANGE", "ir_depth_range_m: [2, 1]"), file="s.yaml", base_dir=tmp_path)
    msg = str(e.value)
    assert "s.yaml:5:" in msg and "ir_depth_range_m" in msg and "expected min < max" in msg and "\n" not in msg, msg
