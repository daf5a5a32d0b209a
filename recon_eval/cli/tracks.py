"""``recon-eval tracks``: point tracks over a sequence against a dataset's truth tracks, with
TAP-Vid's metrics (docs/metrics.md, "Point tracks over a sequence"). Predictions:
:func:`recon_eval.readers.tracks.read_tracks` (one ``.npz`` per camera stream, rows in the order
of the truth's query points)."""
from __future__ import annotations

from pathlib import Path

from recon_eval.cli.scored import no_figures, scored
from recon_eval.errors import InputError
from recon_eval.metrics.tapvid import QUERY_MODES, TAPVID_EVAL_SIZE
from recon_eval.readers.scenegen_dataset import read_dataset
from recon_eval.readers.tracks import read_tracks
from recon_eval.tasks.headlines import tracks_headline
from recon_eval.tasks.tracks import score_streams
from scenegen.dataset.layout import check_name


def arguments(p) -> None:
    p.add_argument("est", help="predicted tracks: a .npz for one stream (with --stream), or a folder of "
                               "<stream>.npz files, one per stream of the dataset")
    p.add_argument("dataset", help="a scenegen sequence dataset with point tracks (sequence.tracks)")
    p.add_argument("--stream", help="the camera stream of a single .npz (default: the dataset's only stream)")
    p.add_argument("--query-mode", choices=QUERY_MODES, default="first",
                   help="TAP-Vid's evaluation frames: 'first' (after the query frame, the default) or "
                        "'strided' (all but the query frame)")
    p.add_argument("--native-resolution", action="store_true",
                   help="thresholds in pixels of the dataset's images instead of TAP-Vid's 256 x 256")


def score(a):
    ds = read_dataset(a.dataset)
    streams = ds.track_streams()
    est = Path(a.est)
    if est.is_dir():
        def path_of(stream):
            return est / f"{check_name('stream', stream)}.npz"
        missing = [s for s in streams if not path_of(s).is_file()]
        if missing:
            raise InputError(f"{est}: no predictions for stream(s) {', '.join(missing)} (expected "
                             f"{', '.join(s + '.npz' for s in missing)})")
    else:
        stream = a.stream or (next(iter(streams)) if len(streams) == 1 else None)
        if stream is None:
            raise InputError(f"{a.dataset} has {len(streams)} streams ({', '.join(streams)}): pass --stream, or a "
                             "folder of <stream>.npz files")
        if stream not in streams:
            raise InputError(f"unknown stream {stream!r}; the dataset's: {', '.join(streams)}")
        streams = {stream: streams[stream]}

        def path_of(_):
            return est
    eval_size = None if a.native_resolution else TAPVID_EVAL_SIZE
    res = score_streams(ds, streams, lambda s, n, t: read_tracks(path_of(s), n, t), query_mode=a.query_mode,
                        eval_size=eval_size)
    inputs = {"est": a.est, "gt": a.dataset, "gt_kind": "scenegen-dataset sequence/tracks", "streams": list(streams),
              "query_mode": a.query_mode, "eval_size": list(eval_size) if eval_size else "native"}
    return inputs, res, no_figures


def metrics(a, res) -> dict:
    """``metrics`` of ``tracks --json``: the names a tracks run gives the same numbers (query mode
    ``first`` at TAP-Vid's 256 x 256); another query mode or ``--native-resolution`` in front."""
    pre = ("" if a.query_mode == "first" else f"{a.query_mode}.") + ("native." if a.native_resolution else "")
    return {pre + k: v for k, v in tracks_headline(res).items()}


COMMANDS = {"tracks": scored(arguments, score, metrics)}
