"""``recon-eval objects`` on a synthetic BOP dataset and COCO keypoint files written in the
official formats (bop_toolkit docs/bop_datasets_format.md; cocodataset.org/#format-data): a
perfect result scores 1, a flip of the symmetric box is correct, the JSON carries the headline
for gates, and bad input is one line naming the file, line or field, exit 2."""
from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import cv2
import numpy as np
import pytest
import trimesh
from scipy.spatial.transform import Rotation

from recon_eval.cli import main
from recon_eval.metrics.objects_depth import DepthRenderer, render_depth

W, H = 48, 36
K = [60.0, 0.0, 23.5, 0.0, 60.0, 17.5, 0.0, 0.0, 1.0]
FLIP = [-1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]


def _pose(rv_deg, t):
    return Rotation.from_rotvec(np.radians(rv_deg)).as_matrix(), np.asarray(t, float)


@pytest.fixture(scope="module")
def bop(tmp_path_factory):
    root = tmp_path_factory.mktemp("bop")
    (root / "models").mkdir()
    wedge = trimesh.convex.convex_hull(np.array([[-30, -20, -10], [35, -20, -10], [-30, 25, -10], [-30, -20, 30.0]]))
    box = trimesh.creation.box(extents=(50.0, 26.0, 18.0))
    info = {}
    for oid, m in ((1, wedge), (2, box)):
        m.export(root / "models" / f"obj_{oid:06d}.ply")
        v = np.asarray(m.vertices)
        info[str(oid)] = {"diameter": float(np.max(np.linalg.norm(v[:, None] - v[None], axis=2)))}
    info["2"]["symmetries_discrete"] = [FLIP]
    (root / "models" / "models_info.json").write_text(json.dumps(info))
    sdir = root / "test" / "000001"
    (sdir / "depth").mkdir(parents=True)
    poses = [(1, *_pose([20, -30, 10], [-30, -10, 350])), (2, *_pose([-15, 25, 40], [30, 15, 330]))]
    gt, info_doc, cam = {}, {}, {}
    Km = np.reshape(K, (3, 3))
    for im in (0, 1):
        depth = np.full((H, W), 600.0)
        for oid, R, t in poses:
            m = wedge if oid == 1 else box
            d = render_depth(m.vertices, m.faces, R, t + [0, 0, 20 * im], Km, W, H)
            depth = np.where((d > 0) & (d < depth), d, depth)
        cv2.imwrite(str(sdir / "depth" / f"{im:06d}.png"), np.round(depth / 0.1).astype(np.uint16))
        gt[str(im)] = [{"obj_id": oid, "cam_R_m2c": R.ravel().tolist(), "cam_t_m2c": (t + [0, 0, 20 * im]).tolist()}
                       for oid, R, t in poses]
        info_doc[str(im)] = [{"visib_fract": 1.0}, {"visib_fract": 1.0}]
        cam[str(im)] = {"cam_K": K, "depth_scale": 0.1}
    for name, doc in (("scene_gt", gt), ("scene_gt_info", info_doc), ("scene_camera", cam)):
        (sdir / f"{name}.json").write_text(json.dumps(doc))
    return root, gt


def _csv(path, gt, flip=False, extra_line=None):
    lines = ["scene_id,im_id,obj_id,score,R,t,time"]
    for im, anns in gt.items():
        for a in anns:
            R = np.reshape(a["cam_R_m2c"], (3, 3))
            if flip and a["obj_id"] == 2:
                R = R @ np.reshape(FLIP, (4, 4))[:3, :3]
            lines.append(f"1,{im},{a['obj_id']},0.9,{' '.join(f'{x:.9f}' for x in R.ravel())},"
                         f"{' '.join(str(x) for x in a['cam_t_m2c'])},0.25")
    if extra_line:
        lines.append(extra_line)
    path.write_text("\n".join(lines) + "\n")
    return path


def _coco(tmp_path, shift_px=0.0):
    kps = [[10, 10, 2, 20, 12, 2, 15, 25, 1], [30, 5, 2, 38, 9, 0, 33, 20, 2]]
    gt = {"images": [{"id": 1, "width": W, "height": H}],
          "categories": [{"id": 1, "name": "figure", "keypoints": ["a", "b", "c"], "skeleton": [[1, 2]],
                          "sigmas": [0.05, 0.06, 0.07]}],
          "annotations": [{"id": i + 1, "image_id": 1, "category_id": 1, "keypoints": k, "num_keypoints": 3,
                           "bbox": [min(k[0::3]), min(k[1::3]), 12, 16], "area": 150.0, "iscrowd": 0}
                          for i, k in enumerate(kps)]}
    res = [{"image_id": 1, "category_id": 1, "score": 0.8,
            "keypoints": [v + (shift_px if j % 3 == 0 else 0) for j, v in enumerate(k)]} for k in kps]
    (tmp_path / "ann.json").write_text(json.dumps(gt))
    (tmp_path / "res.json").write_text(json.dumps(res))
    return tmp_path / "ann.json", tmp_path / "res.json"


def run(argv, capsys):
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def test_perfect_and_flipped_results(bop, tmp_path, capsys):
    root, gt = bop
    ann, res = _coco(tmp_path)
    code, _, err = run(["objects", root, "--bop", _csv(tmp_path / "r.csv", gt), "--coco", res, "--coco-gt", ann,
                        "--json", tmp_path / "o.json", "--html", tmp_path / "o.html", "--quiet"], capsys)
    assert code == 0, err
    doc = json.loads((tmp_path / "o.json").read_text())
    m = doc["metrics"]
    assert m["bop19_ar"] == 1.0 and m["add_recall"] == 1.0 and m["coco_kp_ap"] == 1.0 and m["pck_05"] == 1.0
    assert doc["results"]["bop19"]["n_targets"] == 4 and doc["results"]["bop19"]["mean_time_per_image_s"] == 0.25
    assert (tmp_path / "o.html").stat().st_size > 1000
    code, _, err = run(["objects", root, "--bop", _csv(tmp_path / "f.csv", gt, flip=True), "--json",
                        tmp_path / "f.json", "--quiet"], capsys)
    m = json.loads((tmp_path / "f.json").read_text())["metrics"]
    assert code == 0 and m["bop19_ar_mssd"] == 1.0 and m["adds_recall"] == 1.0 and m["add_recall"] == 0.5


def test_perturbed_keypoints_lower_ap(bop, tmp_path, capsys):
    root, _ = bop
    ann, res = _coco(tmp_path, shift_px=1.5)
    code, _, err = run(["objects", root, "--coco", res, "--coco-gt", ann, "--json", tmp_path / "k.json", "--quiet"],
                       capsys)
    m = json.loads((tmp_path / "k.json").read_text())["metrics"]
    assert code == 0 and 0 < m["coco_kp_ap"] < 1 and m["pck_20"] == 1.0 and m["pck_05"] < 1


BAD_CSV = [
    ("1,0,1,0.9,1 0 0 0 1 0 0 0,0 0 300,0.1", "r.csv:2: field 'R': expected 9"),
    ("1,0,1,0.9,1 0 0 0 1 0 0 0 2,0 0 300,0.1", "r.csv:2: field 'R': not a rotation"),
    ("1,0,1,high,1 0 0 0 1 0 0 0 1,0 0 300,0.1", "r.csv:2: field 'score': not numbers"),
    ("1,0,x,0.9,1 0 0 0 1 0 0 0 1,0 0 300,0.1", "r.csv:2: field 'obj_id': expected an integer"),
    ("1,0,1,0.9,1 0 0 0 1 0 0 0 1,0 0 nan,0.1", "r.csv:2: field 't': non-finite"),
    ("1,0,1,0.9", "r.csv:2: expected 7 comma-separated fields"),
    ("1,7,1,0.9,1 0 0 0 1 0 0 0 1,0 0 300,0.1", "r.csv: scene 1 image 7 is not in the truth"),
]


@pytest.mark.parametrize("line,fragment", BAD_CSV)
def test_bad_result_csv_is_one_line_exit_2(bop, tmp_path, capsys, line, fragment):
    root, _ = bop
    (tmp_path / "r.csv").write_text("scene_id,im_id,obj_id,score,R,t,time\n" + line + "\n")
    (tmp_path / "o.json").write_text("kept")
    code, _, err = run(["objects", root, "--bop", tmp_path / "r.csv", "--json", tmp_path / "o.json"], capsys)
    assert code == 2 and fragment in err and len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert (tmp_path / "o.json").read_text() == "kept"


def test_bad_coco_fields_are_named(bop, tmp_path, capsys):
    root, _ = bop
    ann, res = _coco(tmp_path)
    doc = json.loads(res.read_text())
    doc[1]["keypoints"] = doc[1]["keypoints"][:-1]
    res.write_text(json.dumps(doc))
    code, _, err = run(["objects", root, "--coco", res, "--coco-gt", ann], capsys)
    assert code == 2 and "res.json: [1].keypoints: expected x, y, v triples for 3 keypoints" in err
    doc = json.loads(ann.read_text())
    doc["annotations"][0]["bbox"] = [1, 2, 3]
    ann.write_text(json.dumps(doc))
    code, _, err = run(["objects", root, "--coco", res, "--coco-gt", ann], capsys)
    assert code == 2 and "ann.json: annotations[0].bbox: expected 4 finite numbers" in err


def test_undeclared_sigmas_need_kpt_sigmas(bop, tmp_path, capsys):
    root, _ = bop
    ann, res = _coco(tmp_path)
    doc = json.loads(ann.read_text())
    del doc["categories"][0]["sigmas"]
    ann.write_text(json.dumps(doc))
    code, _, err = run(["objects", root, "--coco", res, "--coco-gt", ann], capsys)
    assert code == 2 and "ann.json: categories[0]: 3 keypoints and no OKS sigmas for them: give --kpt-sigmas" in err
    code, _, err = run(["objects", root, "--coco", res, "--coco-gt", ann, "--kpt-sigmas", "0.05", "--json",
                        tmp_path / "s.json", "--quiet"], capsys)
    doc = json.loads((tmp_path / "s.json").read_text())
    assert code == 0 and doc["metrics"]["coco_kp_ap"] == 1.0 and doc["inputs"]["kpt_sigmas"] == {"1": "--kpt-sigmas"}


def test_gates_read_the_headline(bop, tmp_path, capsys):
    root, gt = bop
    code, _, err = run(["objects", root, "--bop", _csv(tmp_path / "f.csv", gt, flip=True), "--method", "flipper",
                        "--scene", "synthetic", "--json", tmp_path / "f.json", "--quiet"], capsys)
    assert code == 0, err
    gates = tmp_path / "g.yaml"
    gates.write_text("version: 1\ngates:\n"
                     "  - {scene: synthetic, method: flipper, metric: bop19_ar_mssd, op: '>=', threshold: 1.0}\n"
                     "  - {scene: synthetic, method: flipper, metric: adds_recall, op: '>=', threshold: 1.0}\n")
    assert run(["gate", gates, tmp_path / "f.json"], capsys)[0] == 0
    gates.write_text("version: 1\ngates:\n"
                     "  - {scene: synthetic, method: flipper, metric: add_recall, op: '>=', threshold: 0.9,\n"
                     "     reason: a symmetric flip is wrong for ADD}\n")
    assert run(["gate", gates, tmp_path / "f.json"], capsys)[0] == 1


def _reference():
    """The copied bop_toolkit (tests/recon_eval/agreement/bop_toolkit_reference.py)."""
    path = Path(__file__).parents[1] / "agreement" / "bop_toolkit_reference.py"
    spec = importlib.util.spec_from_file_location("bop_toolkit_reference_cli", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_same_ar_as_the_copied_bop_toolkit_on_the_same_files(bop, tmp_path, capsys):
    """The CLI (our readers + metrics) against the reference loop fed from the files as
    bop_toolkit's inout reads them (json, the depth PNG times depth_scale, the PLY vertices)."""
    root, gt = bop
    rng = np.random.default_rng(5)
    lines = ["scene_id,im_id,obj_id,score,R,t,time"]
    for im, anns in gt.items():
        for a in anns:
            R = Rotation.from_rotvec(rng.normal(0, 0.06, 3)).as_matrix() @ np.reshape(a["cam_R_m2c"], (3, 3))
            t = np.asarray(a["cam_t_m2c"]) + rng.normal(0, 4, 3)
            lines.append(f"1,{im},{a['obj_id']},{rng.uniform():.6f},{' '.join(f'{x:.9f}' for x in R.ravel())},"
                         f"{' '.join(f'{x:.6f}' for x in t)},0.25")
    (tmp_path / "p.csv").write_text("\n".join(lines) + "\n")
    code, _, err = run(["objects", root, "--bop", tmp_path / "p.csv", "--json", tmp_path / "p.json", "--quiet"], capsys)
    assert code == 0, err
    ours = json.loads((tmp_path / "p.json").read_text())["metrics"]
    ref = _reference()
    sdir = root / "test" / "000001"
    scene_gt = {int(k): [dict(g, cam_R_m2c=np.reshape(g["cam_R_m2c"], (3, 3)), cam_t_m2c=np.reshape(g["cam_t_m2c"],
                                                                                                    (3, 1)))
                         for g in v] for k, v in json.loads((sdir / "scene_gt.json").read_text()).items()}
    info = {int(k): v for k, v in json.loads((sdir / "scene_gt_info.json").read_text()).items()}
    cam = {int(k): dict(v, cam_K=np.reshape(v["cam_K"], (3, 3)))
           for k, v in json.loads((sdir / "scene_camera.json").read_text()).items()}
    depth = {im: cv2.imread(str(sdir / "depth" / f"{im:06d}.png"), cv2.IMREAD_UNCHANGED).astype(np.float64)
             for im in scene_gt}
    models_info = {int(k): v for k, v in json.loads((root / "models" / "models_info.json").read_text()).items()}
    meshes = {o: trimesh.load(root / "models" / f"obj_{o:06d}.ply", process=False) for o in models_info}
    targets = [{"scene_id": 1, "im_id": im, "obj_id": o, "inst_count": 1} for im in scene_gt for o in (1, 2)]
    ests = [{"scene_id": int(f[0]), "im_id": int(f[1]), "obj_id": int(f[2]), "score": float(f[3]),
             "R": np.array(f[4].split(), float).reshape(3, 3), "t": np.array(f[5].split(), float).reshape(3, 1),
             "time": float(f[6])} for f in (ln.split(",") for ln in lines[1:])]
    ren = DepthRenderer({o: (m.vertices, m.faces) for o, m in meshes.items()}, W, H)
    theirs = ref.evaluate_bop19(ests, targets, scene_gt, info, cam, depth,
                                {o: np.asarray(m.vertices) for o, m in meshes.items()}, models_info, ren, W)
    assert 0 < ours["bop19_ar"] < 1
    for k in ("bop19_ar", "bop19_ar_vsd", "bop19_ar_mssd", "bop19_ar_mspd"):
        assert ours[k] == pytest.approx(theirs[k.replace("bop19_ar", "bop19_average_recall")], abs=1e-12), k
