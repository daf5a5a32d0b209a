"""A LiDAR beside a camera in a rig (scenegen.spec.sensors.lidar through scenegen.pipeline.sensors):
its sweeps written, verified and read back; every beam's range equals an independent cast (trimesh's
ray intersector on the meshes posed by hand at the beam's own time, from the sensor's pose at that
time); a sensor moving at 10 m/s differs from a static-picture sweep by the motion computed by hand;
a resumed run and a second run give the same bytes."""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
import trimesh

from scenegen.dataset import Dataset, verify
from scenegen.geometry.clock import Composed, StaticTrajectory
from scenegen.pipeline.run import render_spec
from scenegen.spec import load_spec
from scenegen.spec.sensors.lidar_beams import beam_cast_by_rays
from scenegen.spec.sensors.lidar_sweep import sweep_fields

sys.path.insert(0, str(Path(__file__).parents[1] / "spec"))
from test_lidar_spec import STREET  # noqa: E402

pytestmark = pytest.mark.render
WALL_X = 19.9  # the wall's face towards the sensor
SPEED = 10.0  # m/s along +x


@pytest.fixture(scope="module")
def rendered(tmp_path_factory):
    root = tmp_path_factory.mktemp("lidar")
    spec = root / "lidar.yaml"
    spec.write_text(STREET)
    out = root / "out"
    render_spec(spec, out, progress=False)
    return spec, out


def tree(path: Path) -> dict:
    return {p.relative_to(path): p.read_bytes() for p in path.rglob("*") if p.is_file()}


def car_box_at(t: float) -> trimesh.Trimesh:
    """The car by hand: a 2 m cube whose centre goes from (10, 6, 0) at 0 s to (10, -6, 0) at 0.2 s."""
    box = trimesh.creation.box(extents=[2, 2, 2])
    box.apply_translation([10.0, 6.0 - 60.0 * min(max(t, 0.0), 0.2), 0.0])
    return box


def test_the_sweeps_are_written_verified_and_read_back(rendered):
    _, out = rendered
    report = verify(out)
    assert report.ok, report.summary()
    d = Dataset(out)
    assert d.streams.of_kind("lidar") == ("seq_lidar",)
    s = d.streams["seq_lidar"]
    assert (s.kind, s.sensor, s.samples) == ("lidar", "l0", 128)  # 2 sweeps of 64 columns
    assert np.array_equal(s.field("sweep"), np.repeat([0, 1], 64))
    # each beam's time and azimuth by hand: column j of sweep k at k / 10 + j / 640 s, channel c
    # 10 us later each, the head turning clockwise at 10 Hz from azimuth 0
    k, j = np.repeat([0, 1], 64), np.tile(np.arange(64), 2)
    t = k[:, None] * 0.1 + j[:, None] / 640.0 + np.arange(4)[None, :] * 10e-6
    assert np.allclose(s.field("beam_time_s"), t, rtol=0, atol=1e-15)
    az = -2.0 * np.pi * 10.0 * (t - k[:, None] * 0.1)
    assert np.abs(np.angle(np.exp(1j * (s.field("azimuth_rad") - az)))).max() < 1e-12
    assert np.allclose(s.field("elevation_rad"), np.radians([-10, -3, 3, 10])[None, :], atol=1e-15)


def test_every_range_equals_trimesh_cast_with_the_beam_at_its_own_time_and_pose(rendered):
    _, out = rendered
    s = Dataset(out).streams["seq_lidar"]
    t = s.field("beam_time_s").reshape(-1)
    az, el = s.field("azimuth_rad").reshape(-1), s.field("elevation_rad").reshape(-1)
    d = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], 1)  # x fwd, y left, z up
    origin = np.stack([SPEED * t, np.zeros_like(t), np.zeros_like(t)], 1)  # the rig's eye, identity rotation
    wall = trimesh.creation.box(extents=[0.2, 40, 10])
    wall.apply_translation([20.0, 0.0, 0.0])
    want = np.full(len(t), np.inf)
    want_obj = np.zeros(len(t), np.uint32)
    loc, ray, _ = trimesh.ray.ray_triangle.RayMeshIntersector(wall).intersects_location(origin, d, multiple_hits=False)
    want[ray] = np.linalg.norm(loc - origin[ray], axis=1)
    want_obj[ray] = 1
    for n in range(len(t)):  # the car posed at each beam's own time
        loc, _, _ = trimesh.ray.ray_triangle.RayMeshIntersector(car_box_at(t[n])).intersects_location(
            origin[n:n + 1], d[n:n + 1], multiple_hits=False)
        if len(loc) and np.linalg.norm(loc[0] - origin[n]) < want[n]:
            want[n], want_obj[n] = np.linalg.norm(loc[0] - origin[n]), 2
    got = s.field("range_m").reshape(-1)
    hit = np.isfinite(want)
    assert hit.sum() > 100 and (want_obj == 2).sum() >= 6 and np.array_equal(np.isfinite(got), hit)
    assert np.abs(got[hit] / want[hit] - 1).max() < 1e-6
    assert np.array_equal(s.field("object_id").reshape(-1), want_obj)
    pw = s.field("point_world_m").reshape(-1, 3)
    assert np.abs(pw[hit] - (origin[hit] + want[hit, None] * d[hit])).max() < 1e-4
    ps = s.field("point_sensor_m").reshape(-1, 3)
    assert np.allclose(ps[hit], want[hit, None] * d[hit], rtol=1e-6)
    # the wall's normal is -x: the incidence angle is the angle between the beam and x
    on_wall = want_obj == 1
    assert np.allclose(s.field("incidence_rad").reshape(-1)[on_wall], np.arccos(d[on_wall, 0]), atol=1e-6)


def test_a_sensor_at_10_mps_differs_from_a_static_picture_by_its_motion(rendered):
    from scenegen.render import load_scene

    spec_path, out = rendered
    spec = load_spec(spec_path)
    scene = load_scene(spec, variant="llvm_ad_rgb")
    lidar = spec.sensors["lidar"]["l0"]
    member = spec.rigs["r"].members[1]
    traj = Composed(spec.view_sets[0].placement.trajectory.trajectory(), StaticTrajectory(member.rig_from_sensor))
    pattern = lidar.scan_pattern()
    by_rays = beam_cast_by_rays(scene.cast_at_times)  # the numpy definition around Mitsuba's ray cast
    moving = sweep_fields(by_rays, lidar, pattern, traj, 0.0, reflectivity={2: 0.9},
                          noise_key=(lidar.seed, "seq_lidar", 0))
    static = sweep_fields(by_rays, lidar, pattern, traj, 0.0, reflectivity={2: 0.9},
                          noise_key=(lidar.seed, "seq_lidar", 0), static_time_s=0.0)
    s = Dataset(out).streams["seq_lidar"]
    first = s.field("sweep") == 0
    for name, value in moving.items():  # the pipeline's sweep (the one-kernel cast_beams), bit for bit
        assert s.field(name)[first].tobytes() == np.ascontiguousarray(value).tobytes(), name
    kernel = sweep_fields(scene.cast_beams, lidar, pattern, traj, 0.0, reflectivity={2: 0.9},
                          noise_key=(lidar.seed, "seq_lidar", 0), static_time_s=0.0)
    assert all(kernel[k].tobytes() == np.ascontiguousarray(static[k]).tobytes() for k in static)
    wall = (moving["object_id"] == 1) & (static["object_id"] == 1)
    cos = np.cos(moving["elevation_rad"]) * np.cos(moving["azimuth_rad"])
    dt = moving["beam_time_s"]  # seconds after the sweep's start (0 s)
    assert wall.sum() > 50 and dt[wall].max() > 0.09
    # by hand: r = (19.9 - 10 t) / (cos el cos az), so the sweep is shorter by 10 t / (cos el cos az)
    assert np.allclose(static["range_m"][wall], WALL_X / cos[wall], rtol=1e-6)
    assert np.allclose(moving["range_m"][wall] - static["range_m"][wall], -SPEED * dt[wall] / cos[wall], atol=2e-5)
    # the moving car too: a static picture sees it where it was at 0 s, the sweep where each beam met it
    assert not np.array_equal(moving["object_id"] == 2, static["object_id"] == 2)


def test_a_resumed_run_and_a_second_run_give_the_same_bytes(rendered, tmp_path):
    spec, out = rendered
    files = tree(out)
    render_spec(spec, out, progress=False, resume=True)
    assert tree(out) == files
    again = tmp_path / "again"
    render_spec(spec, again, progress=False)
    stream_files = {p: b for p, b in files.items() if p.parts[0] == "streams"}
    assert stream_files and {p: b for p, b in tree(again).items() if p.parts[0] == "streams"} == stream_files


def read_pcd(path: Path) -> np.ndarray:
    """A binary PCD v0.7 read from the format's documentation (pointclouds.org, "The PCD file
    format"): header lines up to DATA, then WIDTH x HEIGHT packed records of FIELDS / SIZE / TYPE."""
    data = path.read_bytes()
    head, fields = {}, None
    pos = 0
    while True:
        end = data.index(b"\n", pos)
        line = data[pos:end].decode("ascii")
        pos = end + 1
        if line.startswith("#"):
            continue
        key, *vals = line.split()
        head[key] = vals
        if key == "DATA":
            break
    assert head["VERSION"] == ["0.7"] and head["DATA"] == ["binary"]
    kinds = {("F", "4"): "<f4", ("F", "8"): "<f8", ("U", "2"): "<u2", ("U", "4"): "<u4"}
    fields = np.dtype([(n, kinds[(t, s)]) for n, t, s in zip(head["FIELDS"], head["TYPE"], head["SIZE"])])
    n = int(head["WIDTH"][0]) * int(head["HEIGHT"][0])
    assert int(head["POINTS"][0]) == n
    return np.frombuffer(data, fields, count=n, offset=pos)


def test_exports_read_back_with_independent_readers(rendered, tmp_path):
    from scenegen.export import export

    _, out = rendered
    s = Dataset(out).streams["seq_lidar"]
    first = s.field("sweep") == 0
    r = s.field("measured_range_m")[first].reshape(-1)
    keep = np.isfinite(r)
    pts = s.field("measured_point_m")[first].reshape(-1, 3)[keep]
    inten = s.field("intensity")[first].reshape(-1)[keep]
    ring = s.field("ring")[first].reshape(-1)[keep]
    assert 50 < keep.sum() < len(r) and np.all((inten > 0) & (inten <= 1))
    for fmt in ("kitti-velodyne", "nuscenes-lidar", "lidar-pcd", "lidar-ply"):
        export(out, fmt, tmp_path / fmt)
    kitti = np.fromfile(tmp_path / "kitti-velodyne/seq_lidar/velodyne/000000.bin", dtype=np.float32).reshape(-1, 4)
    assert np.array_equal(kitti, np.column_stack([pts, inten]).astype(np.float32))
    nus = np.fromfile(tmp_path / "nuscenes-lidar/seq_lidar/000000.pcd.bin", dtype=np.float32).reshape(-1, 5)
    assert np.array_equal(nus[:, :4], kitti) and np.array_equal(nus[:, 4], ring.astype(np.float32))
    pcd = read_pcd(tmp_path / "lidar-pcd/seq_lidar/000000.pcd")
    assert np.array_equal(np.column_stack([pcd["x"], pcd["y"], pcd["z"]]), pts.astype(np.float32))
    assert np.array_equal(pcd["ring"], ring) and np.array_equal(pcd["range"], r[keep].astype(np.float32))
    t = s.field("beam_time_s")[first].reshape(-1)[keep]
    assert np.array_equal(pcd["time"], t - s.time_s[0])
    ply = trimesh.load(tmp_path / "lidar-ply/seq_lidar/000001.ply")
    second = s.field("sweep") == 1
    keep1 = np.isfinite(s.field("measured_range_m")[second].reshape(-1))
    assert np.array_equal(np.asarray(ply.vertices), s.field("measured_point_m")[second].reshape(-1, 3)[keep1]
                          .astype(np.float32).astype(np.float64))


def test_recon_eval_scores_a_hand_deskewed_sweep_and_the_raw_one(rendered, tmp_path):
    """De-skewed by hand with the sensor's motion (10 m/s along +x, no rotation) to the sweep's
    start: the error is the range noise's (none here: exact to float32), the raw cloud's the skew."""
    import json

    from recon_eval.cli import main as recon_main
    from scenegen.export import export

    _, out = rendered
    export(out, "kitti-velodyne", tmp_path / "k")
    raw = tmp_path / "k/seq_lidar/velodyne/000001.bin"
    s = Dataset(out).streams["seq_lidar"]
    rows = s.field("sweep") == 1
    keep = np.isfinite(s.field("measured_range_m")[rows].reshape(-1))
    t = s.field("beam_time_s")[rows].reshape(-1)[keep]
    pts = np.fromfile(raw, np.float32).reshape(-1, 4)[:, :3].astype(np.float64)
    fixed = pts + np.column_stack([SPEED * (t - 0.1), 0 * t, 0 * t])  # into the LiDAR frame at 0.1 s
    np.save(tmp_path / "fixed.npy", fixed)
    assert recon_main(["lidar-deskew", str(tmp_path / "fixed.npy"), str(out), "--sweep", "1", "--quiet",
                       "--json", str(tmp_path / "d.json")]) == 0
    assert recon_main(["lidar-deskew", str(raw), str(out), "--sweep", "1", "--quiet",
                       "--json", str(tmp_path / "r.json")]) == 0
    fixed_res = json.loads((tmp_path / "d.json").read_text())["results"]["deskew"]
    raw_res = json.loads((tmp_path / "r.json").read_text())["results"]["deskew"]
    assert fixed_res["error_m"]["max"] < 2e-5  # float32 file rounding at 20 m
    assert raw_res["error_m"]["max"] == pytest.approx(SPEED * (t.max() - 0.1), rel=1e-3)
    np.save(tmp_path / "short.npy", fixed[:-1])
    assert recon_main(["lidar-deskew", str(tmp_path / "short.npy"), str(out), "--sweep", "1"]) == 2
