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
from scenegen.dataset.lazy import lazy_exports

# name -> the submodule it comes from; loaded on first use (scenegen.dataset.lazy)
__getattr__, __all__ = lazy_exports(__name__, {
    "cameras": ("ViewCamera",),
    "errors": ("DatasetError", "DatasetMismatchError"),
    "journal": ("load_current_manifest",),
    "layout": ("CAMERAS", "MANIFEST", "mesh_path", "view_paths"),
    "manifest": ("FORMAT", "FORMAT_VERSION"),
    "reader": ("Dataset",),
    "stream_writer": ("StreamWriter",),
    "streams": ("StreamField", "StreamSchema"),
    "truth": ("TRUTH_KEYS", "TruthKind", "check_truth"),
    "verify": ("VerifyReport", "verify"),
    "view_files": ("encode_view", "software_versions", "write_view_files"),
    "writer": ("DatasetWriter",),
})
