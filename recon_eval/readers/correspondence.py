"""A dense correspondence file (``crossview/corr/<i>/<j>.exr``, docs/crossview.md) read on its own,
through scenegen's codec (:func:`scenegen.dataset.crossview.decode_correspondence_channels`), as the
metrics' :class:`recon_eval.metrics.features.CorrespondenceMap`. Inside a dataset use
:meth:`recon_eval.readers.scenegen_dataset.DatasetTruth.correspondence`."""
from __future__ import annotations

from pathlib import Path

from recon_eval.errors import InputError
from recon_eval.metrics.features import CorrespondenceMap
from recon_eval.readers.native import read_exr
from scenegen.dataset.crossview import decode_correspondence_channels


def read_correspondence_map(path) -> CorrespondenceMap:
    """Channels u, v, z (float32, widened exactly) and state of a correspondence file."""
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{p}: no such file (expected a correspondence EXR: u, v, z, state)")
    try:
        channels = read_exr(p)
    except ValueError as exc:  # the codec's message names the file
        raise InputError(str(exc)) from None
    try:
        return CorrespondenceMap.of(decode_correspondence_channels(channels))
    except KeyError as exc:
        raise InputError(f"{p}: {exc.args[0]}") from None
