"""``recon-eval cam-imu``: Kalibr camchain-imucam results against the truth camchain, with planted
errors recovered in closed form; bad files refused with file:line."""
import json

import numpy as np
from scipy.spatial.transform import Rotation

from recon_eval.cli import main


def run(argv):
    return main([str(a) for a in argv] + ["--quiet"])


def _camchain(cams):
    out = []
    for k, (T, shift) in enumerate(cams):
        rows = "".join(f"  - [{', '.join(f'{v:.17g}' for v in r)}]\n" for r in T)
        out.append(f"cam{k}:\n  camera_model: pinhole\n  intrinsics: [400, 400, 320, 240]\n  T_cam_imu:\n{rows}"
                   f"  timeshift_cam_imu: {shift!r}\n")
    return "".join(out)


def _T(R, t):
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, t
    return T


def test_planted_extrinsic_and_time_offset_errors(tmp_path):
    R0 = Rotation.from_euler("xyz", [90, 0, 90], degrees=True).as_matrix()
    gt = [(_T(R0, [0.05, -0.01, 0.02]), -0.004), (_T(R0, [-0.06, -0.01, 0.02]), -0.004)]
    # estimate: cam0 rotated by 0.5 deg about the IMU's z, its centre 3 mm off along x of the IMU frame
    dR = Rotation.from_euler("z", 0.5, degrees=True).as_matrix()
    c_gt = -R0.T @ gt[0][0][:3, 3]
    R_imu_cam = dR @ R0.T
    c_est = c_gt + [0.003, 0, 0]
    T_est0 = _T(R_imu_cam.T, -R_imu_cam.T @ c_est)
    (tmp_path / "gt.yaml").write_text(_camchain(gt))
    (tmp_path / "est.yaml").write_text(_camchain([(T_est0, -0.0015), gt[1]]))
    out = tmp_path / "r.json"
    assert run(["cam-imu", tmp_path / "est.yaml", tmp_path / "gt.yaml", "--json", out]) == 0
    d = json.loads(out.read_text())
    r0, r1 = d["results"]["cam0"], d["results"]["cam1"]
    assert abs(r0["rot_err_deg"] - 0.5) < 1e-12 and abs(r0["trans_err_m"] - 0.003) < 1e-15
    assert abs(r0["time_offset_err_s"] - 0.0025) < 1e-15
    assert r1["rot_err_deg"] < 1e-6 and r1["trans_err_m"] == 0 and r1["time_offset_err_s"] == 0
    assert d["metrics"]["cam0.abs_time_offset_err_s"] == r0["abs_time_offset_err_s"]


def test_bad_camchains_are_refused(tmp_path, capsys):
    (tmp_path / "gt.yaml").write_text(_camchain([(np.eye(4), 0.0)]))
    bad = tmp_path / "est.yaml"
    for text, want in [("cam0:\n  T_cam_imu:\n  - [1, 0, 0, 0]\n", "est.yaml:3: cam0.T_cam_imu: expected 4 rows"),
                       (_camchain([(2 * np.eye(4), 0.0)]), "expected a rigid transform"),
                       ("imu0:\n  T_i_b: []\n", "est.yaml:1: imu0: expected camN: blocks"),
                       (_camchain([(np.eye(4), 0.0)]).replace("cam0", "cam1"), "est.yaml: no cam0")]:
        bad.write_text(text)
        assert run(["cam-imu", bad, tmp_path / "gt.yaml"]) == 2
        err = capsys.readouterr().err
        assert want in err and "Traceback" not in err, err
