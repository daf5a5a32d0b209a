"""What one run can do: the largest sizes and counts a spec may ask for, each with its reason
(docs/scene_spec.md, "Limits"). They are checked while the spec is parsed, before anything is
allocated, so a hostile or mistyped size fails in milliseconds with its file:line instead of an
out-of-memory error (or hours of work) in the renderer."""
from __future__ import annotations

from scenegen.assets.checks import MAX_MESH_FACES, MAX_MESH_FILE_BYTES, MAX_TEXTURE_PIXELS

__all__ = ["MAX_IMAGE_SIDE_PX", "MAX_IMAGE_PIXELS", "MAX_SPP", "MAX_VIEWS", "MAX_BOARD_SIDE", "MAX_TRACKS",
           "MAX_MESH_FACES", "MAX_MESH_FILE_BYTES", "MAX_TEXTURE_PIXELS"]

#: Largest image side, pixels. Why: Mitsuba's film and our per-pixel truth are dense arrays of
#: the image; 16384 is the largest side of common sensors and displays times two, and the largest
#: texture side GPUs address.
MAX_IMAGE_SIDE_PX = 16384
#: Most pixels of one image (width x height): 2^26 = 67 million (e.g. 8192 x 8192). Why: a view's
#: truth is derived in float64 (~250 bytes per pixel with the image and the truth files being
#: encoded), about 17 GB at this size: the most a large workstation holds.
MAX_IMAGE_PIXELS = 1 << 26
#: Most samples per pixel. Why: Monte Carlo noise falls as 1/sqrt(spp): at 65,536 spp it is 1/256
#: of one sample's, below the 8- and 16-bit quantisation of the stored images; a billion spp
#: would render a 64 x 48 image for days.
MAX_SPP = 1 << 16
#: Most views of one run (all view sets, rig members counted). Why: cameras.json and the manifest
#: list every view; the writer and its journal are measured up to 100,000 views
#: (docs/performance.md); a million views is ~1 GB of manifest: split such a run into datasets.
MAX_VIEWS = 1_000_000
#: Most corners, squares or markers along one side of a calibration board. Why: the board is
#: rasterised with every edge on a texel boundary; 512 squares of the smallest raster already
#: make a texture at the image-size limit.
MAX_BOARD_SIDE = 512
#: Most point tracks of one camera stream (``sequence.tracks.count``). Why: each track is every
#: frame's position (two float32) and two flags, 10 bytes a frame, and is cast through every
#: frame's scene: a million tracks over 100 frames are 1 GB of truth; each query point is also a
#: distinct surface pixel of a query frame, so more than the image holds cannot be drawn.
MAX_TRACKS = 1_000_000
#: The asset limits (mesh triangles and file bytes, texture pixels) live with the asset builders
#: that check them: scenegen.assets.checks (MAX_MESH_FACES, MAX_MESH_FILE_BYTES, MAX_TEXTURE_PIXELS).
