"""Readers at the edge: one module per file format, each converting to recon_eval's conventions
(metres, OpenCV pixels and camera axes, cam_from_world poses, NaN = missing). Every reader raises
:class:`recon_eval.errors.InputError` naming the file and what was expected."""
