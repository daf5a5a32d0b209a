"""The numpy core: every convention of the project, stated once, and the geometry built on it.

Nothing here imports Mitsuba or Dr.Jit (the camera arithmetic takes its array operations as an
argument; the renderer passes Dr.Jit's). The evaluator (recon_eval) and the generator import the
same functions, so a convention cannot drift between what is written and what is scored.

* :mod:`.conventions`: axes, pixels, depth vs range, and the one conversion to each foreign
  convention (Mitsuba, OpenGL/NeRF, Blender, COLMAP).
* :mod:`.rotation`: rotation validity, quaternions, rotation vectors, angles.
* :mod:`.pose`: :class:`~scenegen.geometry.pose.Rigid3`, named by frames (``cam_from_world``).
* :mod:`.camera`: the camera-model registry and :class:`~scenegen.geometry.camera.Camera`.
* :mod:`.twoview`: relative pose, E, F, epipoles, plane homographies, Sampson and epipolar errors.
* :mod:`.rectify`: Bouguet rectification, rectification maps, disparity from depth.
* :mod:`.optics`: thin lens, shutter, motion, chromatic aberration (lens and time geometry).
* :mod:`.color`: the sRGB transfer functions and bit-depth conversions of stored images.
* :mod:`.seeds`: how every seed of the project is derived from the user's seeds.
"""
