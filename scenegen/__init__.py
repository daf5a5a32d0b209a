"""scenegen: synthetic multi-view renders with exact ground truth.

Every convention is stated once, in :mod:`scenegen.geometry`; the dataset contract (paths,
codecs, reader, writer) is :mod:`scenegen.dataset`; Mitsuba is imported only by
:mod:`scenegen.render`. The layers: docs/architecture.md.
"""
__version__ = "0.1.0"
