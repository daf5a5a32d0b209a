"""``recon-eval cam-imu``: a camera-IMU calibration in Kalibr's results format
(``camchain-imucam.yaml``: ``T_cam_imu``, ``timeshift_cam_imu`` per camera) against the truth in the
same format, as ``scenegen export --format euroc`` writes it (``camchain.yaml``); cameras matched
by their ``camN`` key (docs/metrics.md, "Visual-inertial odometry")."""
from __future__ import annotations

from recon_eval.cli.scored import scored
from recon_eval.errors import InputError
from recon_eval.metrics.cam_imu import cam_imu_error
from recon_eval.readers.kalibr import read_kalibr_camchain


def arguments(p) -> None:
    p.add_argument("est", help="Kalibr camchain-imucam.yaml of the calibration (T_cam_imu, timeshift_cam_imu)")
    p.add_argument("gt", help="the truth's Kalibr camchain.yaml (scenegen export --format euroc)")


def score(a):
    est = {c.name: c for c in read_kalibr_camchain(a.est)}
    gt = read_kalibr_camchain(a.gt)
    missing = [c.name for c in gt if c.name not in est]
    if missing:
        raise InputError(f"{a.est}: no {', '.join(missing)} (the truth {a.gt} has {', '.join(c.name for c in gt)})")
    res = {c.name: cam_imu_error(c.name, est[c.name].cam_from_imu, est[c.name].timeshift_cam_imu_s, c.cam_from_imu,
                                 c.timeshift_cam_imu_s) for c in gt}
    inputs = {"est": a.est, "gt": a.gt, "cameras": [c.name for c in gt],
              "extra_cameras": sorted(set(est) - {c.name for c in gt})}
    return inputs, res, list


def headline(a, res) -> dict:
    return {f"{k}.{f}": getattr(r, f) for k, r in res.items()
            for f in ("rot_err_deg", "trans_err_m", "abs_time_offset_err_s")}


COMMANDS = {"cam-imu": scored(arguments, score, headline)}
