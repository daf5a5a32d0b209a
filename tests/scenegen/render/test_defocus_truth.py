"""Defocus truth (issue 33): the circle of confusion stored for a pixel (truth/<view>_coc.exr)
equals the thin-lens formula and the blur the renderer draws of a point there.

The point: a 1 mm square area light on the optical axis (through the centre pixel's ray, so the
truth pass hits it) 0.35 m before a lens focused at 2 m (f/1.4, fx 160 px, 200 um pixels): the
thin lens spreads it over a disc of radius R = fx A |1/2 - 1/0.35| = 4.3 px. The image's intensity
second moment per axis is R^2 / 4 (a uniform disc) plus the source's own width^2 / 12 (0.46 px
wide) plus the pixel's 1/12 (box filter), so R_measured = 2 sqrt(var - w^2 / 12 - 1 / 12).
Measured at 1024 spp (ldsampler): 4.338 px against the stored 4.310 px (+0.6 %, the centroid within
0.02 px of the centre pixel); the point is sampled sparsely (few of a pixel's samples reach the
1 mm source through the aperture), so at 256 spp the same measure is 4.11 px (-4.6 %, centroid
0.6 px off) and with the independent sampler at 1024 spp +3.6 %: hence 5 %.
"""
import numpy as np
import pytest

from scenegen.dataset import Dataset
from scenegen.pipeline.run import render_spec
from scenegen.spec.source import SpecSource

TOL_REL = 0.05  # Monte Carlo noise of a sparsely sampled point (module docstring); the imaging audit's bound is 10 %
POINT_SPEC = """
name: point
render: {spp: 1024, max_depth: 2}
truth: {defocus: true}
lights:
  - {type: area, name: dot, size: [0.001, 0.001], position: [0, 0, 0.35], look_at: [0, 0, 0], radiance: 40000}
cameras:
  cam:
    size: [65, 65]
    fx: 160
    lens: {f_number: 1.4, focus_distance_m: 2.0, pixel_pitch_um: 200}
views:
  - {camera: cam, look_at: [{eye: [0, 0, 0], target: [0, 0, 1], up: [0, -1, 0]}]}
"""


@pytest.mark.render
def test_stored_coc_is_the_formula_and_the_rendered_blur(tmp_path):
    out = tmp_path / "point"
    render_spec(SpecSource(POINT_SPEC, "<point>", str(tmp_path)), out, progress=False, show_warnings=False)
    d = Dataset(out)
    (view,) = d.views
    t, coc = d.truth(view), d.coc_radius_px(view)
    assert t["valid"][32, 32] and t["valid"].sum() == 1  # the centre pixel's ray hits the 1 mm source
    A = 160 * 200e-6 / (2 * 1.4)
    R = 160 * A * abs(1 / 2.0 - 1 / float(t["depth_z"][32, 32]))
    assert coc[32, 32] == pytest.approx(R, rel=1e-6) and R > 4.0
    img = d.linear_image(view).mean(axis=-1).astype(np.float64)
    v, u = np.mgrid[0:65, 0:65]
    w = img / img.sum()
    cu, cv = (w * u).sum(), (w * v).sum()
    var = 0.5 * ((w * (u - cu) ** 2).sum() + (w * (v - cv) ** 2).sum())
    width_px = 160 * 0.001 / 0.35
    r_measured = 2 * np.sqrt(var - width_px ** 2 / 12 - 1 / 12)
    assert abs(r_measured - coc[32, 32]) < TOL_REL * coc[32, 32], (r_measured, coc[32, 32])
