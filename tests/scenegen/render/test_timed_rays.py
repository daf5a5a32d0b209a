"""Ray casts with a time per ray (render.timed.timed_first_hit_at_times): a cube crossing parallel
rays at 10 m/s is hit by exactly the rays whose own time puts it on them (closed form), with the
times given per ray or as a table gathered by index."""
import numpy as np
import pytest

from scenegen.spec import parse_spec

pytestmark = pytest.mark.render

SPEC = """
name: timed_rays
sequence: {fps: 10, frames: 3}
render: {spp: 4}
objects:
  - name: cube
    shape: {type: box, size: [0.2, 0.2, 0.2]}
    trajectory:
      interpolation: linear
      keyframes:
        - {time_s: 0, translation: [-1, 0, 0]}
        - {time_s: 0.2, translation: [1, 0, 0]}
lights: [{type: constant, radiance: 1.0}]
cameras: {cam: {size: [32, 24], fx: 30}}
views:
  - camera: cam
    trajectory:
      keyframes:
        - {time_s: 0, eye: [0, -2, 0], target: [0, 0, 0]}
"""


def test_each_ray_meets_the_cube_where_it_is_at_the_ray_time():
    import drjit as dr
    import mitsuba as mi

    from scenegen.render import load_scene
    from scenegen.render.arrays import to_jit
    from scenegen.render.timed import timed_first_hit_at_times

    spec = parse_spec(SPEC)
    built = load_scene(spec, variant="llvm_ad_rgb")
    ts = built.timed()
    rng = np.random.default_rng(26)
    n = 4000
    x0 = rng.uniform(-1.2, 1.2, n)
    times = rng.uniform(-0.02, 0.22, n)  # beyond the keyframes the cube holds its end pose
    centre_x = -1.0 + 10.0 * np.clip(times, 0.0, 0.2)
    gap = np.abs(x0 - centre_x)
    want = gap < 0.1
    clear = np.abs(gap - 0.1) > 1e-6  # not on the cube's edge

    def vec(a):
        return mi.Vector3d(*[to_jit(mi.Float64, np.ascontiguousarray(a[:, i]), np.float64) for i in range(3)])

    origin = vec(np.stack([x0, np.full(n, -2.0), np.zeros(n)], 1))
    direction = vec(np.tile([0.0, 1.0, 0.0], (n, 1)))
    t, hit, *_ = timed_first_hit_at_times(ts, origin, direction, times, built.timeline, False, coherent=False)
    dr.eval(t, hit)
    got, dist = hit.numpy(), t.numpy()
    assert want.sum() > 100 and (~want).sum() > 100
    assert np.array_equal(got[clear], want[clear])
    assert np.abs(dist[got] - 1.9).max() < 1e-6  # the front face, y = -0.1
    # the same times as a table of 50, each ray gathering its own
    table = np.linspace(-0.02, 0.22, 50)
    idx = rng.integers(0, 50, n)
    centre_x = -1.0 + 10.0 * np.clip(table[idx], 0.0, 0.2)
    want = np.abs(x0 - centre_x) < 0.1
    clear = np.abs(np.abs(x0 - centre_x) - 0.1) > 1e-6
    _, hit, *_ = timed_first_hit_at_times(ts, origin, direction, table, built.timeline, False, coherent=False,
                                          index=to_jit(mi.UInt32, idx.astype(np.uint32), np.uint32))
    dr.eval(hit)
    assert np.array_equal(hit.numpy()[clear], want[clear])
