"""The structured-light runners and ``recon-eval codes`` on the analytic projector-lit dataset
(tests/recon_eval/conftest.py: a plane and a sphere, the Gray-code sequence sampled at each camera
pixel centre's exact projector coordinate, stored as the renderer stores it)."""
import json
import shutil

import numpy as np
import pytest

from recon_eval.cli import main as cli_main
from recon_eval.errors import NotApplicable
from recon_eval.readers.structured_light import projector_views
from recon_eval.runners import run_method


@pytest.fixture(scope="module")
def gray_run(sl_dataset, tmp_path_factory):
    out = tmp_path_factory.mktemp("run") / "gray"
    return out, run_method("sl-gray-code", sl_dataset, out)


def test_reader_maps_the_files_bit_order_to_the_decoders(sl_dataset, procam):
    pv, = projector_views(sl_dataset)
    gray = [f for f in pv.frames if f.kind == "gray" and f.axis == "u" and not f.inverse]
    assert [f.bit for f in gray] == list(range(7)) and pv.frames[0].kind == "white"
    assert pv.images.shape == (30, 120, 160) and pv.lit.sum() == procam.lit.sum()


def test_gray_runner_reads_every_code_and_stays_within_the_bound(gray_run, procam):
    out, doc = gray_run
    m = doc["metrics"]
    # the patterns are sampled at each pixel centre's exact projector coordinate (no pixel area):
    # every lit pixel decodes to its truth column and row, the points within half a column
    assert m["code_agreement"] == m["code_agreement_clear"] == 1.0 and m["code_completeness"] == 1.0
    assert m["code_err_mean_px"] == 0.0
    assert m["depth_within_bound"] == 1.0 and m["depth_mean_abs_mm"] < 7.0
    assert m["fscore_mean"] == doc["results"]["scan_0000.cloud"]["fscore"] > 0.0
    codes = np.load(out / "scan_0000" / "codes.npy")
    assert codes.shape == (120, 160, 2) and np.isnan(codes[~procam.lit]).mean() > 0.99  # shadows are not decoded
    assert (out / "result.json").is_file() and (out / "scan_0000" / "cloud.ply").is_file()


def test_ray_ray_runner_agrees(sl_dataset, tmp_path):
    m = run_method("sl-gray-code-rays", sl_dataset, tmp_path / "rays")["metrics"]
    assert m["code_agreement"] == 1.0 and m["depth_mean_abs_mm"] < 7.0


def test_phase_runner_is_not_applicable_to_gray_codes(sl_dataset, tmp_path):
    with pytest.raises(NotApplicable, match="phase"):
        run_method("sl-phase-shift", sl_dataset, tmp_path / "phase")


def test_codes_command_scores_a_code_map_and_refuses_a_wrong_shape(gray_run, sl_dataset, tmp_path, capsys):
    out, doc = gray_run
    js = tmp_path / "codes.json"
    assert cli_main(["codes", str(out / "scan_0000" / "codes.npy"), str(sl_dataset), "--cloud",
                     str(out / "scan_0000" / "cloud.ply"), "--json", str(js), "-q"]) == 0
    m = json.loads(js.read_text())["metrics"]
    assert m["code_agreement"] == doc["metrics"]["code_agreement"] == 1.0
    assert m["fscore"] == pytest.approx(doc["metrics"]["fscore_mean"])
    bad = tmp_path / "bad.npy"
    np.save(bad, np.zeros((10, 10, 2)))
    capsys.readouterr()
    assert cli_main(["codes", str(bad), str(sl_dataset), "-q"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "bad.npy" in err[0] and "(120, 160, 2)" in err[0]


@pytest.mark.parametrize("doc", ['{"format": "scenegen.patterns/1"}', '[1, 2]',
                                 '{"format": "scenegen.patterns/1", "projector": {}, "patterns": [{"index": 0}]}'])
def test_a_broken_sequence_file_is_one_line_and_exit_2(sl_dataset, tmp_path, capsys, doc):
    root = tmp_path / "ds"
    shutil.copytree(sl_dataset, root)
    (root / "patterns" / "scan_0000" / "sequence.json").write_text(doc)
    capsys.readouterr()
    assert cli_main(["run", "sl-gray-code", str(root), "-o", str(tmp_path / "out"), "-q"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "sequence.json" in err[0] and "Traceback" not in err[0]
