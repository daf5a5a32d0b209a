"""scenegen: synthetic multi-view renders with exact ground truth.

Conventions are stated once in :mod:`scenegen.geometry.conventions`. Importing this package does not import
Mitsuba; the renderer is loaded only by :mod:`scenegen.render`.
"""
__version__ = "0.1.0"
