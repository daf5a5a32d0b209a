"""EMVA 1288 photon transfer measured from a dataset's files alone (docs/image_formation.md,
"Worked example: EMVA 1288 from the files").

    .venv/bin/python docs/examples/emva1288.py            # every preset, datasets under out/emva1288/
    .venv/bin/python docs/examples/emva1288.py smartphone:6

The scene (:func:`flat_field_spec`) is the lab set-up of EMVA 1288 R4.0 (sec. 6): a camera with
``imaging: {preset: ..., raw: true}`` looking into a uniform Lambertian light box, an illumination
series of view sets (``lights`` factors: dark, then levels up to 70 % of saturation), two frames
per level (two views: two frame seeds). Planning the levels uses the preset's numbers, as a lab
sets its light source; the measurement (:func:`measure`) reads only the dataset: the views' levels
from ``cameras.json`` (their ``lights``) and each view's mosaic and black level from its DNG.

Per level, from the two frames A and B (EMVA 1288 R4.0, eqs. 27-28 / sec. 6.3):
``mu_y = (mean(A) + mean(B)) / 2``, ``sigma_y^2 = var(A - B) / 2`` (the fixed patterns cancel);
``K`` is the slope through the origin of ``sigma_y^2 - sigma_y.dark^2`` against
``mu_y - mu_y.dark``; the temporal dark noise ``sigma_d = sqrt(sigma_y.dark^2 - 1/12) / K``, which
EMVA allows only for ``sigma_y.dark^2 >= 0.24 DN^2`` (below, quantisation hides it and only the
upper limit ``0.40 / K`` may be given); the dark-current electrons ``(mu_y.dark - black) / K``.
"""
from __future__ import annotations

import json
import sys
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from scenegen.dataset import Dataset
from scenegen.imaging.chain import electrons_per_radiance
from scenegen.imaging.presets import PRESETS

#: Levels as fractions of the saturation signal at the image centre (EMVA fits up to 70 %).
FRACTIONS = (0.05, 0.18, 0.31, 0.44, 0.57, 0.70)
#: EMVA 1288: sigma_y.dark^2 must reach 0.24 DN^2 for sigma_d to be measured; else 0.40 / K is
#: only an upper limit (sqrt(0.24 - 1/12) = 0.40).
DARK_VAR_MIN_DN2 = 0.24
QUANTISATION_VAR_DN2 = 1.0 / 12.0
SIZE = (320, 240)  # 76,800 pixels: a variance to sqrt(2 / 76,800) = 0.5 % per level (1 sigma)


def flat_field_spec(preset: str, gain_db: float = 0.0, size=SIZE, fractions=FRACTIONS) -> str:
    """The YAML of the flat-field series for ``preset`` at ``gain_db``."""
    p = PRESETS[preset]
    s = p.sensor
    K = s.system_gain(gain_db)
    e_sat = min(s.saturation_capacity_e, (s.white_level_dn - s.black_level_dn) / K)
    radiance_sat = e_sat / float(np.max(electrons_per_radiance(p)))  # panel radiance at saturation
    eye = "{eye: [0, 0, 0], target: [1, 0, 0]}"
    sets = [f"  - {{name: dark, camera: cam, lights: {{box: 0}}, look_at: [{eye}, {eye}]}}"]
    sets += [f"  - {{name: level, camera: cam, lights: {{box: {f * radiance_sat!r}}}, "
             f"look_at: [{eye}, {eye}]}}" for f in fractions]
    return "\n".join([
        f"name: emva1288_{preset}",
        f"description: EMVA 1288 flat-field series of the {preset} preset at {gain_db:g} dB",
        "seed: 1288",
        "render: {spp: 1, max_depth: 1}   # the light box is seen directly: no Monte Carlo noise",
        "lights:",
        "  - {type: area, name: box, size: [40, 40], position: [1, 0, 0], look_at: [0, 0, 0], "
        "radiance: 1}",
        "cameras:",
        "  cam:",
        f"    size: [{size[0]}, {size[1]}]",
        f"    fx: {0.9 * size[0]}",
        f"    imaging: {{preset: {preset}, exposure: {{gain_db: {gain_db}}}, raw: true}}",
        "views:",
        *sets,
        "",
    ])


@dataclass(frozen=True)
class Emva1288:
    """The measurement from the files (DN, electrons) and what the camera declares."""

    levels: int  # light levels besides dark
    K_dn_per_e: float  # system gain, slope of the photon transfer curve
    dark_mean_dn: float  # mu_y.dark
    dark_var_dn2: float  # sigma_y.dark^2
    sigma_d_e: float | None  # temporal dark noise, None where EMVA allows only an upper limit
    sigma_d_upper_e: float  # 0.40 / K (EMVA's upper limit where sigma_y.dark^2 < 0.24 DN^2)
    dark_current_e: float  # (mu_y.dark - black level) / K, electrons in the exposure
    black_level_dn: float  # from the DNG
    model_K_dn_per_e: float  # the camera's declared values (cameras.json), for comparison
    model_sigma_d_e: float  # sqrt(read noise^2 + dark-current electrons) at this exposure
    model_dark_mean_dn: float  # black + K * dark-current electrons


def measure(dataset_dir) -> Emva1288:
    """EMVA 1288 photon transfer from a flat-field dataset's files (cameras.json and the DNGs)."""
    d = Dataset(dataset_dir)
    levels: dict[tuple, list[str]] = {}
    for view in d.views:  # the views of one level share their lights (cameras.json)
        levels.setdefault(tuple(sorted(d.view_info(view)["lights"].items())), []).append(view)
    mu, var, black = [], [], None
    for views in sorted(levels.values()):
        a, b = (d.raw(v) for v in views[:2])  # two frames of one level
        ya, yb = a.mosaic.astype(np.float64), b.mosaic.astype(np.float64)
        mu.append(0.5 * (ya.mean() + yb.mean()))
        var.append(0.5 * np.var(ya - yb))
        black = a.black_level_dn
    mu, var = np.array(mu), np.array(var)
    dark = int(np.argmin(mu))
    x, y = np.delete(mu - mu[dark], dark), np.delete(var - var[dark], dark)
    K = float(np.sum(x * y) / np.sum(x * x))  # slope through the origin
    measurable = var[dark] >= DARK_VAR_MIN_DN2
    sigma_d = float(np.sqrt(var[dark] - QUANTISATION_VAR_DN2) / K) if measurable else None
    # what the camera declares, from cameras.json (not used above)
    spec = d.spec
    cam = spec["cameras"][d.view_info(d.views[0])["camera_name"]]["imaging"]
    s, t = cam["sensor"], cam["exposure"]["exposure_time_s"]
    K_model = spec["imaging_used"]["cameras"][d.view_info(d.views[0])["camera_name"]]["system_gain_dn_per_e"]
    mu_dark_e = s["dark_current_e_per_s"] * t
    return Emva1288(levels=len(mu) - 1, K_dn_per_e=K, dark_mean_dn=float(mu[dark]),
                    dark_var_dn2=float(var[dark]), sigma_d_e=sigma_d,
                    sigma_d_upper_e=float(np.sqrt(DARK_VAR_MIN_DN2 - QUANTISATION_VAR_DN2) / K),
                    dark_current_e=float((mu[dark] - black) / K), black_level_dn=float(black),
                    model_K_dn_per_e=float(K_model),
                    model_sigma_d_e=float(np.sqrt(s["dark_noise_e"] ** 2 + mu_dark_e)),
                    model_dark_mean_dn=float(s["black_level_dn"] + K_model * mu_dark_e))


def table_row(name: str, r: Emva1288) -> str:
    """One Markdown table row: measured vs declared."""
    sd = f"{r.sigma_d_e:.3f}" if r.sigma_d_e is not None else f"< {r.sigma_d_upper_e:.2f} (limit)"
    return (f"| {name} | {r.K_dn_per_e:.5f} / {r.model_K_dn_per_e:.5f} "
            f"({100 * (r.K_dn_per_e / r.model_K_dn_per_e - 1):+.2f} %) | {r.dark_var_dn2:.3f} | "
            f"{sd} / {r.model_sigma_d_e:.3f} | {r.dark_mean_dn:.4f} / {r.model_dark_mean_dn:.4f} "
            f"({r.dark_mean_dn - r.model_dark_mean_dn:+.4f}) |")


CASES = (("machine_vision", 0.0), ("smartphone", 0.0), ("smartphone", 6.0), ("dslr", 0.0))
HEADER = ("| preset, gain | K DN/e-: files / model | sigma_y.dark^2 DN^2 | sigma_d e-: files / model "
          "| dark mean DN: files / model |\n|---|---|---|---|---|")


def main(argv) -> int:
    from scenegen.cli import main as scenegen  # the CLI renders (Mitsuba); measure() needs none

    cases = [(a.split(":")[0], float(a.split(":")[1]) if ":" in a else 0.0) for a in argv] or CASES
    root = Path("out/emva1288")
    print(HEADER)
    for preset, gain in cases:
        out = root / f"{preset}_{gain:g}dB"
        spec = root / f"{preset}_{gain:g}dB.yaml"
        spec.parent.mkdir(parents=True, exist_ok=True)
        spec.write_text(flat_field_spec(preset, gain))
        if not (out / "manifest.json").is_file():
            assert scenegen(["render", str(spec), "-o", str(out), "-q"]) == 0
        r = measure(out)
        print(table_row(f"{preset}, {gain:g} dB", r))
        (root / f"{preset}_{gain:g}dB.json").write_text(json.dumps(asdict(r), indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
