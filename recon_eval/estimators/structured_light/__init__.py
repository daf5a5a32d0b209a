"""Structured-light decoding and triangulation in numpy (no maintained library in the project's
dependencies has them: OpenCV's ``structured_light`` module is in opencv-contrib only):

* :mod:`.graycode`: per-bit pattern-vs-inverse thresholding, Gray to binary, column / row codes;
* :mod:`.phase`: N-step wrapped phase and hierarchical temporal unwrapping;
* :mod:`.triangulate`: camera ray against a projector column's plane (exact for a pinhole
  projector, Newton-refined onto the column's curved surface for a distorted one), ray-ray
  midpoints for (column, row) codes, and the depth bound of a code's quantisation;
* :mod:`.homography`: Moreno and Taubin's local homographies, board corners into the projector.

The code rules (bit order, pixel index, phase origin) are :mod:`scenegen.geometry.sl_codes`.
"""
