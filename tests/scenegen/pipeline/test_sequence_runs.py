"""Sequences are runs like any other: bitwise determinism, --frames and --resume give the bytes of
the one-shot run (sequence truth and tracks included), and the moving objects are rendered
where the truth has them (frame by frame, and within a blurred exposure)."""
import json

import numpy as np
import pytest

from scenegen.cli import main
from scenegen.dataset import Dataset
from scenegen.dataset.codecs import read_json

pytestmark = pytest.mark.render

SPEC = """
name: seqrun
render: {spp: 4, max_depth: 2, motion_subframes: 4}
sequence: {fps: 20, frames: 3, flow_steps: [1], tracks: {count: 24, query_frames: [0]}}
objects:
  - name: floor
    shape: {type: plane, size: [3, 3]}
    material: {type: diffuse, texture: {type: checkerboard, params: {squares_u: 6, squares_v: 6}}}
  - name: cube
    shape: {type: box, size: [0.3, 0.3, 0.3]}
    material: {type: diffuse, color: [0.8, 0.1, 0.1]}
    trajectory:
      keyframes:
        - {time_s: 0.0, translation: [-0.3, 0, 0.15]}
        - {time_s: 0.05, translation: [0.0, 0.05, 0.15], rotation_deg: [0, 0, 30]}
        - {time_s: 0.1, translation: [0.3, 0, 0.15], rotation_deg: [0, 0, 60]}
  - name: late
    shape: {type: blob, radius: 0.1, amplitude: 0}
    visible_s: [0.04, 0.2]
    trajectory: {keyframes: [{time_s: 0, translation: [0.3, -0.4, 0.1]}]}
lights: [{type: constant, radiance: 1}]
cameras:
  cam: {size: [48, 36], fx: 40, shutter: {exposure_s: 0.01}}
views:
  - camera: cam
    trajectory:
      keyframes:
        - {time_s: 0.0, eye: [0, -2, 1.5], target: [0, 0, 0]}
        - {time_s: 0.1, eye: [0.2, -2, 1.5], target: [0, 0, 0]}
"""


@pytest.fixture(scope="module")
def spec_file(tmp_path_factory):
    p = tmp_path_factory.mktemp("seqrun") / "scene.yaml"
    p.write_text(SPEC)
    return p


@pytest.fixture(scope="module")
def rendered(spec_file, tmp_path_factory):
    out = tmp_path_factory.mktemp("seqrun_out") / "a"
    assert main(["render", str(spec_file), "-o", str(out), "-q"]) == 0
    return out


def _files(root):
    return json.loads((root / "manifest.json").read_text())["files"]


def test_a_sequence_run_is_bitwise_deterministic(spec_file, rendered, tmp_path):
    out = tmp_path / "b"
    assert main(["render", str(spec_file), "-o", str(out), "-q"]) == 0
    a, b = _files(rendered), _files(out)
    assert a == b
    for rel in ("sequence/index.json", "sequence/objects.json", "sequence/tracks/cam.npz",
                "sequence/motion/cam_0000/cam_0001.exr", "sequence/flow/cam_0001/cam_0000.flo"):
        assert rel in a


def test_frames_and_resume_give_the_one_shot_bytes(spec_file, rendered, tmp_path):
    out = tmp_path / "c"
    assert main(["render", str(spec_file), "-o", str(out), "-q", "--frames", "1"]) == 0
    assert "sequence/index.json" not in _files(out)
    assert main(["render", str(spec_file), "-o", str(out), "-q", "--resume", "--frames", "0-2"]) == 0
    assert _files(out) == _files(rendered)


def test_objects_are_rendered_where_the_truth_has_them(rendered):
    ds = Dataset(rendered)
    objs = read_json(rendered / "sequence/objects.json")["frames"]
    ids = [ds.truth(v)["object_id"] for v in ds.views]
    assert not np.array_equal(ids[0], ids[2])  # the cube moved
    assert not (ids[0] == 3).any() and (ids[1] == 3).any()  # the late blob appeared at 0.04 s
    assert [f["objects"]["late"]["present"] for f in objs] == [False, True, True]
    for v, oid in zip(ds.views, ids):  # the red cube's pixels are red in the render
        img = ds.linear_image(v)
        cube = oid == 2
        assert img[cube][:, 0].mean() > 2 * img[cube][:, 1].mean()


def test_the_typed_reader_gives_the_sequence_truth(rendered):
    ds = Dataset(rendered)
    seq = ds.sequence
    assert seq.index.timestamps_s == (0.0, 0.05, 0.1)
    assert ("cam_0000", "cam_0001", 1) in seq.index.pairs and "cam" in seq.index.streams
    m = seq.motion("cam_0000", "cam_0001")
    flo = seq.flow("cam_0000", "cam_0001")
    ok = np.isfinite(flo[..., 0])
    assert np.abs(m.flow[ok] - flo[ok]).max() < 1e-4  # u, v stored as float32, .flo the difference
    poses = seq.object_poses(2)
    assert poses["late"][1] and np.allclose(poses["cube"][0].t, [0.3, 0, 0.15])
    assert len(seq.tracks("cam")) == 24


def test_tapvid_export_holds_the_tracks_in_tapvid_form(rendered, tmp_path):
    assert main(["export", str(rendered), "--format", "tapvid", "-o", str(tmp_path / "tv")]) == 0
    ds = Dataset(rendered)
    tr = ds.sequence.tracks("cam")
    with np.load(tmp_path / "tv" / "cam.npz", allow_pickle=False) as z:
        assert sorted(z.files) == ["occluded", "points", "query_points", "video"]
        assert z["video"].shape == (3, 36, 48, 3) and z["video"].dtype == np.uint8
        assert np.array_equal(z["video"][1], ds.image("cam_0001"))
        # TAP-Vid's normalised coordinates: image corner (0, 0), opposite corner (1, 1)
        assert np.allclose(z["points"] * [48, 36] - 0.5, tr.tracks_xy, atol=1e-4, equal_nan=True)
        assert np.array_equal(z["occluded"], tr.occluded)
        q = z["query_points"]
        assert np.array_equal(q[:, 0], tr.query_points[:, 0])
        assert np.allclose(q[:, 1] * 36 - 0.5, tr.query_points[:, 1], atol=1e-4)
    assert main(["export", str(rendered), "--format", "tum", "-o", str(tmp_path / "tum")]) == 0
    first = (tmp_path / "tum" / "cam.txt").read_text().splitlines()
    assert "time_s" in first[0] and first[2].startswith("0.050000 ")


def test_preview_export_draws_the_tracks(rendered, tmp_path):
    import cv2
    from PIL import Image

    from scenegen.export.tracks_video import _colour

    assert main(["export", str(rendered), "--format", "tracks-video", "-o", str(tmp_path / "pv")]) == 0
    assert sorted(p.name for p in (tmp_path / "pv").iterdir()) == ["cam.gif", "cam.mp4"]
    ds = Dataset(rendered)
    tr = ds.sequence.tracks("cam")
    gif = Image.open(tmp_path / "pv" / "cam.gif")
    assert gif.n_frames == 3 and gif.size == (48, 36)
    cap = cv2.VideoCapture(str(tmp_path / "pv" / "cam.mp4"))
    assert int(cap.get(cv2.CAP_PROP_FRAME_COUNT)) == 3 and int(cap.get(cv2.CAP_PROP_FRAME_WIDTH)) == 48
    gif.seek(2)
    frame = np.asarray(gif.convert("RGB")).astype(int)
    n = int(np.flatnonzero(~tr.occluded[:, 2])[-1])  # drawn last: on top
    x, y = np.rint(tr.tracks_xy[n, 2]).astype(int)
    assert np.abs(frame[y, x] - _colour(n)).max() < 60  # its dot, in its colour (GIF palette)


def test_kitti_flow_export_reads_back_with_the_devkit_rule(rendered, tmp_path):
    import cv2

    from scenegen.dataset.crossview import VISIBLE

    assert main(["export", str(rendered), "--format", "kitti-flow", "-o", str(tmp_path / "k")]) == 0
    ds = Dataset(rendered)
    m = ds.sequence.motion("cam_0000", "cam_0001")
    for kind in ("occ", "noc"):
        bgr = cv2.imread(str(tmp_path / f"k/training/flow_{kind}/000000_10.png"), cv2.IMREAD_UNCHANGED)
        rgb = bgr[..., ::-1].astype(np.float64)  # the devkit's readFlowField, independently
        valid = rgb[..., 2] > 0
        flow = (rgb[..., :2] - 2 ** 15) / 64.0
        want = np.isfinite(m.flow[..., 0]) & ((m.state == VISIBLE) if kind == "noc" else True)
        assert np.array_equal(valid, want)
        assert np.abs(flow[valid] - m.flow[valid]).max() <= 1 / 64
    assert (tmp_path / "k/training/image_2/000001_11.png").is_file()


STEREO_SPEC = """
name: seqstereo
render: {spp: 1, max_depth: 2}
sequence: {fps: 10, frames: 2}
objects:
  - name: floor
    shape: {type: plane, size: [4, 4]}
  - name: ball
    shape: {type: sphere, radius: 0.3}
    trajectory:
      interpolation: linear
      keyframes:
        - {time_s: 0.0, translation: [-0.4, 0, 0.3]}
        - {time_s: 0.1, translation: [0.4, 0.2, 0.3]}
lights: [{type: constant, radiance: 1}]
cameras: {cam: {size: [64, 48], fx: 50}}
rigs: {st: {type: stereo, left: cam, right: cam, baseline_m: 0.2}}
views:
  - rig: st
    trajectory: {keyframes: [{time_s: 0, eye: [0, -2.5, 1.5], target: [0, 0, 0.2]}]}
crossview: {pairs: none, flow: false, stereo: true}
"""


def test_stereo_frames_of_a_moving_scene_are_cast_at_their_time(tmp_path):
    """The rectified disparity of each frame of a moving stereo rig equals f B / Z of an
    independent analytic cast of the rectified left camera with the ball where it is then."""
    from scenegen.dataset.codecs import read_pfm

    (tmp_path / "s.yaml").write_text(STEREO_SPEC)
    assert main(["render", str(tmp_path / "s.yaml"), "-o", str(tmp_path / "o"), "-q"]) == 0
    ds = Dataset(tmp_path / "o")
    for k, centre in enumerate(([-0.4, 0, 0.3], [0.4, 0.2, 0.3])):
        calib = read_json(tmp_path / f"o/crossview/stereo/st_left_{k:04d}/calib.json")
        K, (W, H) = np.array(calib["K"]), calib["size"]
        R = np.array(calib["cam_left_from_world"]["R"])
        t = np.array(calib["cam_left_from_world"]["t"])
        C = -R.T @ t
        u, v = np.meshgrid(np.arange(W, dtype=float), np.arange(H, dtype=float))
        d_cam = np.stack([(u - K[0, 2]) / K[0, 0], (v - K[1, 2]) / K[1, 1], np.ones_like(u)], -1).reshape(-1, 3)
        d = d_cam @ R  # world directions (not unit): depth along the axis = the ray parameter
        s_floor = np.where(d[:, 2] < 0, -C[2] / d[:, 2], np.inf)
        oc = C - np.asarray(centre)
        a, b, c = np.sum(d * d, 1), 2 * d @ oc, oc @ oc - 0.3 ** 2
        disc = b * b - 4 * a * c
        with np.errstate(invalid="ignore"):
            s_ball = np.where(disc >= 0, (-b - np.sqrt(disc)) / (2 * a), np.inf)
        z = np.minimum(s_floor, s_ball).reshape(H, W)
        want = K[0, 0] * 0.2 / z
        got = read_pfm(tmp_path / f"o/crossview/stereo/st_left_{k:04d}/disp_left.pfm")
        ball = (s_ball < s_floor).reshape(H, W)
        ok = np.isfinite(got) & np.isfinite(want)
        assert ball.sum() > 50 and np.abs(got[ok] - want[ok]).max() < 1e-3, k
    assert ds.crossview.index.stereo == (("st_left_0000", "st_right_0000"), ("st_left_0001", "st_right_0001"))


def test_a_moving_board_has_its_corner_truth_at_each_frame(tmp_path):
    import cv2

    from scenegen.geometry.pose import Rigid3

    spec = STEREO_SPEC.replace("""  - name: ball
    shape: {type: sphere, radius: 0.3}""", """  - name: ball
    target: {type: aruco_grid, markers_x: 2, markers_y: 2, marker_m: 0.2, separation_m: 0.05,
             dictionary: DICT_4X4_50}""").replace("translation: [-0.4, 0, 0.3]}", "translation: [-0.4, 0, 0.3], "
                                                  "rotation_deg: [0, 0, 0]}").replace(
        "translation: [0.4, 0.2, 0.3]}", "translation: [0.4, 0.2, 0.3], rotation_deg: [0, 0, 30]}").replace(
        "stereo: true}", "stereo: false, targets: true}")
    (tmp_path / "s.yaml").write_text(spec)
    assert main(["render", str(tmp_path / "s.yaml"), "-o", str(tmp_path / "o"), "-q"]) == 0
    ds = Dataset(tmp_path / "o")
    board = read_json(tmp_path / "o/scene/targets/ball.json")
    for k in range(2):
        wfo, _ = ds.sequence.object_poses(k)["ball"]
        w0, _ = ds.sequence.object_poses(0)["ball"]  # scene/targets/ holds the board at frame 0
        wfb = wfo @ w0.inverse() @ Rigid3.from_dict(board["world_from_board"])
        want = wfb.apply(np.array(board["points_board"], float))
        for member in ("left", "right"):
            view = f"st_{member}_{k:04d}"
            truth = read_json(tmp_path / f"o/crossview/targets/{view}.json")["boards"]["ball"]
            assert np.abs(np.array(truth["points_world"]) - want).max() < 1e-9
            cam, pose = ds.camera(view)
            uv, _ = cv2.projectPoints(want, cv2.Rodrigues(pose.R)[0], pose.t, cam.K, np.zeros(5))
            assert np.abs(np.array(truth["uv"], float) - uv.reshape(-1, 2)).max() < 1e-6


def test_a_rolling_shutter_sequence_is_deterministic_and_resumes(tmp_path):
    """The rolling-shutter paths (per-row casts with the moving objects at each row's time, time
    slices in the render, rows solved in the other frame) give the same bytes run to run and
    through --frames + --resume."""
    spec = tmp_path / "rolling.yaml"
    spec.write_text(SPEC.replace("shutter: {exposure_s: 0.01}", "shutter: {exposure_s: 0.004, rolling_readout_s: 0.02}"))
    assert "rolling_readout_s" in spec.read_text()
    runs = []
    for name, frames in (("a", None), ("b", None), ("c", "1")):
        out = tmp_path / name
        assert main(["render", str(spec), "-o", str(out), "-q"] + (["--frames", frames] if frames else [])) == 0
        if frames:
            assert main(["render", str(spec), "-o", str(out), "-q", "--resume"]) == 0
        runs.append(_files(out))
    assert runs[0] == runs[1] == runs[2]
