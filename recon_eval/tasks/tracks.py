"""Scoring a sequence's point tracks stream by stream, as TAP-Vid scores videos: the truth tracks
of each camera stream (:meth:`recon_eval.readers.scenegen_dataset.DatasetTruth.tracks_truth`)
against a prediction, then the plain mean over the streams."""
from __future__ import annotations

from recon_eval.metrics.tapvid import mean_over_videos, tapvid_metrics


def score_streams(ds, streams, prediction_of, *, query_mode: str, eval_size) -> dict:
    """{stream: TapVidResult} of the predictions ``prediction_of(stream, n_tracks, n_frames)`` ->
    (tracks (N, T, 2), occluded (N, T)) for ``streams``, plus ``mean_over_streams``: TAP-Vid's mean over the
    streams (its videos)."""
    out = {}
    for stream in streams:
        truth = ds.tracks_truth(stream)
        n, t = truth.occluded.shape
        pred, occ = prediction_of(stream, n, t)
        out[stream] = tapvid_metrics(truth.query_points, truth.tracks_xy, truth.occluded, pred, occ,
                                     image_size=tuple(int(x) for x in truth.image_size), query_mode=query_mode,
                                     eval_size=eval_size)
    out["mean_over_streams"] = mean_over_videos(list(out.values()))
    return out
