"""Every case of the hostile command-line corpus (tests/hostile/command_corpus.py) through
``scenegen.cli.main`` or ``recon_eval.cli.main`` in-process: exit code 2, one line naming the
option or the tampered file, the expected fragment, no traceback, nothing written; and every
Python API case: its exception type (never AttributeError) and a message naming the argument.
The dataset cases render one small sequence (48 x 36, 3 frames) once and tamper a copy each,
re-signing the manifest (what anyone who edits a dataset can do)."""
from __future__ import annotations

import shutil
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))
from command_corpus import CASES, SEQUENCE_SPEC, api_cases  # noqa: E402
from hostile_data import resign, run_cli  # noqa: E402

from recon_eval.cli import main as recon_main  # noqa: E402
from scenegen.cli import main  # noqa: E402

MAINS = {"scenegen": main, "recon-eval": recon_main}


@pytest.fixture(scope="module")
def spec_file(tmp_path_factory):
    p = tmp_path_factory.mktemp("command_corpus") / "seq.yaml"
    p.write_text(SEQUENCE_SPEC)
    return p


@pytest.fixture(scope="module")
def sequence_dataset(spec_file, tmp_path_factory):
    out = tmp_path_factory.mktemp("command_corpus_data") / "seq"
    assert main(["render", str(spec_file), "-o", str(out), "-q"]) == 0
    return out


def _run(cid, tool, argv, fragment, names, spec_file, out, data=None, est=None):
    fill = {"spec": spec_file, "out": out, "data": data, "est": est}
    args = [a.format(**fill) for a in argv]
    before = {p for p in out.rglob("*")}
    code, _, err = run_cli(MAINS[tool], args)
    assert "Traceback" not in err and code == 2, (code, err)
    lines = [ln for ln in err.strip().splitlines() if not ln.startswith("usage:")]
    assert len(lines) == 1 and lines[0].startswith(f"{tool}: error: ") and fragment in lines[0], err
    if names == "data":  # the tampered file, by its path in the dataset
        assert str(data) in lines[0], err
    assert {p for p in out.rglob("*")} == before, f"{cid} wrote something"


OPTION_CASES = [c for c in CASES if c[3] is None]
DATA_CASES = [c for c in CASES if c[3] is not None]


def test_the_corpus_covers_every_export_that_reads_the_index():
    assert {c[2][3] for c in DATA_CASES if c[2][0] == "export"} >= {"kitti-flow", "sintel", "tapvid", "tracks-video"}
    assert len({c[0] for c in CASES}) == len(CASES)


@pytest.mark.parametrize("cid,tool,argv,tamper,fragment,names", OPTION_CASES, ids=[c[0] for c in OPTION_CASES])
def test_hostile_option(spec_file, tmp_path, cid, tool, argv, tamper, fragment, names):
    _run(cid, tool, argv, fragment, names, spec_file, tmp_path)


@pytest.mark.render
@pytest.mark.parametrize("cid,tool,argv,tamper,fragment,names", DATA_CASES, ids=[c[0] for c in DATA_CASES])
def test_hostile_dataset(spec_file, sequence_dataset, tmp_path, cid, tool, argv, tamper, fragment, names):
    data = tmp_path / "data"
    shutil.copytree(sequence_dataset, data)
    est = tmp_path / "est.npz"
    shutil.copy(sequence_dataset / "sequence" / "tracks" / "cam.npz", est)  # a well-formed prediction
    tamper(data)
    resign(data)
    out = tmp_path / "out"
    out.mkdir()
    _run(cid, tool, argv, fragment, names, spec_file, out, data, est)


@pytest.mark.render
def test_the_untampered_dataset_exports_and_scores(sequence_dataset, tmp_path):
    """The cases fail for their tamper, not for the dataset: the same commands pass on it."""
    for fmt in ("kitti-flow", "sintel", "tapvid", "tracks-video"):
        assert run_cli(main, ["export", sequence_dataset, "--format", fmt, "-o", tmp_path / fmt, "-q"])[0] == 0
    est = sequence_dataset / "sequence" / "tracks" / "cam.npz"
    assert run_cli(recon_main, ["tracks", est, sequence_dataset, "--stream", "cam", "--quiet",
                                "--json", tmp_path / "t.json"])[0] == 0


@pytest.mark.parametrize("cid,call,kind,fragment", api_cases(), ids=[c[0] for c in api_cases()])
def test_hostile_api_call(cid, call, kind, fragment):
    with pytest.raises(Exception) as info:
        call()
    assert type(info.value) is kind and not isinstance(info.value, AttributeError), repr(info.value)
    assert fragment in str(info.value), str(info.value)


@pytest.mark.render
@pytest.mark.parametrize("target,written", [("[0, 0, 1.8]", 0), ("[0, 0, 1.2]", 312)])
def test_fewer_tracks_than_asked_are_said_not_silent(tmp_path, target, written):
    """A count the query frames' surface cannot fill (issue 25: 812 tracks written for 10^9, exit
    0, no word) is a warning with the count written; a frame with no surface at all used to crash
    the correspondence kernel (Dr.Jit: incompatible sizes 0 and 1)."""
    spec = tmp_path / "short.yaml"
    spec.write_text(SEQUENCE_SPEC.replace("count: 24", "count: 1700").replace("frames: 3", "frames: 2")
                    .replace("target: [0, 0, 0]}", f"target: {target}}}"))
    with pytest.warns(RuntimeWarning, match=f"stream 'cam': {written:,} of 1,700 tracks written"):
        assert main(["render", str(spec), "-o", str(tmp_path / "out"), "-q"]) == 0
    from scenegen.dataset import Dataset

    assert len(Dataset(tmp_path / "out").sequence.tracks("cam")) == written
