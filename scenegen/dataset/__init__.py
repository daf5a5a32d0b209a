"""The dataset: the contract between the generator and the evaluator, and the only place that
knows paths (docs/dataset_format.md, docs/crossview.md).

* :mod:`.layout`: every relative path, and the checks on names that become paths;
* :mod:`.codecs`: the file formats, encode and decode together (JSON, PNG, EXR, NPY, PFM, KITTI
  PNG16, FLO, PLY);
* :mod:`.files`: atomic writes and SHA-256;
* :mod:`.manifest`, :mod:`.cameras`, :mod:`.truth`, :mod:`.crossview`: what each file holds
  (:mod:`.truth`: :class:`TruthKind`, the per-pixel truth kinds named once);
* :mod:`.writer`: :class:`DatasetWriter` (atomic, hashed, resumable), with :mod:`.journal`
  (the manifest's append-only journal while a run writes) and :mod:`.view_files` (a view's files);
* :mod:`.streams`: sensor streams beside the views (schema, chunks), written by
  :class:`StreamWriter` (:mod:`.stream_writer`), read by ``Dataset.streams`` (:mod:`.stream_reader`);
* :mod:`.reader` and :mod:`.crossview_reader`: :class:`Dataset`, typed access to everything;
* :mod:`.verify`: re-hash a folder against its manifest.

Nothing here imports Mitsuba or Dr.Jit.
"""
from scenegen.dataset.cameras import ViewCamera
from scenegen.dataset.errors import DatasetError, DatasetMismatchError
from scenegen.dataset.journal import load_current_manifest
from scenegen.dataset.layout import CAMERAS, MANIFEST, mesh_path, view_paths
from scenegen.dataset.manifest import FORMAT, FORMAT_VERSION
from scenegen.dataset.reader import Dataset
from scenegen.dataset.stream_writer import StreamWriter
from scenegen.dataset.streams import StreamField, StreamSchema
from scenegen.dataset.truth import TRUTH_KEYS, TruthKind, check_truth
from scenegen.dataset.verify import VerifyReport, verify
from scenegen.dataset.view_files import encode_view, software_versions, write_view_files
from scenegen.dataset.writer import DatasetWriter

__all__ = [
    "CAMERAS", "MANIFEST", "FORMAT", "FORMAT_VERSION", "TRUTH_KEYS", "TruthKind", "DatasetError",
    "DatasetMismatchError",
    "ViewCamera", "view_paths", "mesh_path", "check_truth", "encode_view", "write_view_files",
    "software_versions", "DatasetWriter", "Dataset", "VerifyReport", "verify", "load_current_manifest",
    "StreamField", "StreamSchema", "StreamWriter",
]
