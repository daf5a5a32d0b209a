"""A rolling shutter with a moving object in the render (issue 16): the image shows the object
where its trajectory has it at each row's time, as the truth does.

A black bar slides sideways at 3 m/s in front of a uniformly lit background, seen by a still
camera with a 40 ms readout and no exposure time: row v is exposed at ``readout (v / (H - 1) -
0.5)``, so the bar's image is sheared by ~4.9 px from top to bottom. The renderer splits the
frame's time span into ``motion_subframes`` slices, each rendered with the bar at the slice's
centre and only the samples of the rows exposed then: a row sees the bar at its slice's centre
time, at most half a slice (0.15 px here) from its own time. Each row's bar centre (the centroid
of the missing light; pixels are box-filtered, so the coverage is exact up to the Monte Carlo
noise of the edge pixels) is compared with the bar's analytic position at the row's time, and
with the truth's per-row object mask.
"""
import numpy as np
import pytest

from scenegen.spec import parse_spec, resolve_views

pytestmark = pytest.mark.render

W, H, F = 96, 72, 80.0
SPEED, DEPTH, READOUT, SUB = 3.0, 2.0, 0.04, 16
# Per-row centre vs the row's time: half a slice of motion (0.15 px) plus the Monte Carlo noise of
# two edge pixels at 256 spp (~0.03 px each); measured: see the printed figure.
TOL_ROW_PX = 0.25
SPEC = f"""
name: rolling_bar
render: {{spp: 256, max_depth: 2, motion_subframes: {SUB}}}
objects:
  - name: bar
    shape: {{type: box, size: [0.3, 0.01, 2.0]}}
    transform: {{translation: [0, 0, 0]}}
    material: {{type: diffuse, color: 0.0}}
    motion: {{linear_velocity_mps: [{SPEED}, 0, 0]}}
lights: [{{type: constant, radiance: 1.0}}]
cameras: {{cam: {{size: [{W}, {H}], fx: {F}, shutter: {{rolling_readout_s: {READOUT}}}}}}}
views:
  - camera: cam
    look_at: [{{eye: [0, -{DEPTH}, 0], target: [0, 0, 0], up: [0, 0, 1]}}]
"""


def test_rendered_rows_see_the_bar_at_their_own_time():
    from scenegen.pipeline.view import render_view_data
    from scenegen.render import load_scene

    spec = parse_spec(SPEC)
    view = resolve_views(spec)[0]
    built = load_scene(spec, variant="llvm_ad_rgb")
    _, linear, truth, _ = render_view_data(spec, built, 0, view, spp=256, seed=1)
    dark = 1.0 - linear[..., 1].astype(np.float64)  # the missing light: 1 on the bar, 0 around it
    cols = np.arange(W, dtype=np.float64)
    rows = np.arange(H, dtype=np.float64)
    centre = (dark * cols).sum(1) / dark.sum(1)
    # analytic: the bar's centre x = SPEED t at the row's time, its front face 1.995 m away
    t = READOUT * (rows / (H - 1) - 0.5)
    expected = F * SPEED * t / (DEPTH - 0.005) + (W - 1) / 2
    err = np.abs(centre - expected)
    mask_centre = np.array([np.flatnonzero(r).mean() for r in truth["object_id"] == 1])
    print(f"shear {expected[-1] - expected[0]:.2f} px over the frame; rendered row centres within "
          f"{err.max():.3f} px of the row times' positions (median {np.median(err):.3f}); the truth's "
          f"per-row mask centres within {np.abs(mask_centre - expected).max():.3f} px")
    assert err.max() < TOL_ROW_PX
    assert np.abs(mask_centre - expected).max() <= 0.5 + 1e-9  # pixel-centre sampling of a sharp edge
    # a render with the bar at one time for every row (a global shutter's) would be off by the shear
    assert expected[-1] - expected[0] > 4.0
