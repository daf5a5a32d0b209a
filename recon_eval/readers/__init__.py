"""Readers at the edge: one module per file format, each converting to recon_eval's conventions
(metres, OpenCV pixels and camera axes, cam_from_world poses, NaN = missing), on top of scenegen's
codecs where the format is one of the dataset's. :mod:`.registry` says which reader reads a path;
:mod:`.scenegen_dataset` is the evaluator's view of a scenegen dataset. Every reader raises
:class:`recon_eval.errors.InputError` naming the file and what was expected."""
