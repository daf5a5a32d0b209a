"""Procedural and file textures for scene assets (pure numpy / OpenCV; no Mitsuba).

Every function returns a float32 array of shape (H, W, 3) holding LINEAR reflectance in [0, 1]
(not sRGB-encoded values). Image rows run top to bottom and columns left to right; with the
project's UV convention (:mod:`scenegen.geometry.conventions`) u runs along columns and v along rows with
v = 0 at row 0, so ``texture[round(v * H - 0.5), round(u * W - 0.5)]`` is the texel at (u, v).

Sizes are given as ``size_px``: an int for a square texture or ``(width_px, height_px)`` (OpenCV's
order). Everything random is drawn from ``np.random.default_rng(seed)``: the same arguments give a
bitwise-identical array. The random textures (noise, speckle, natural) tile seamlessly (they are
periodic over the image), so a UV seam (sphere, cylinder, torus) shows no discontinuity.

The spec layer builds textures through :func:`make_texture` (kind name + params dict + seed);
image files are read by :mod:`scenegen.assets.texture_files`.
"""
from __future__ import annotations

import inspect
from typing import Callable

import numpy as np

from scenegen.assets.checks import MAX_TEXTURE_PIXELS
from scenegen.assets.texture_files import load_image

Color = tuple[float, float, float]

# --- helpers -----------------------------------------------------------------------------------


def _size_wh(size_px) -> tuple[int, int]:
    """(width, height) from an int or a (width, height) pair; both >= 1."""
    if isinstance(size_px, (int, np.integer)):
        w = h = int(size_px)
    else:
        try:
            w, h = (int(s) for s in size_px)
        except (TypeError, ValueError):
            raise ValueError(f"size_px must be an int or (width, height), got {size_px!r}") \
                from None
    if w < 1 or h < 1:
        raise ValueError(f"size_px must be positive, got {size_px!r}")
    if w * h > MAX_TEXTURE_PIXELS:
        raise ValueError(f"size_px {w} x {h} is more than {MAX_TEXTURE_PIXELS:,} pixels (MAX_TEXTURE_PIXELS, "
                         "docs/scene_spec.md 'Limits')")
    return w, h


def _color(c, name: str) -> np.ndarray:
    """A linear RGB reflectance as (3,) float64; a single number means grey."""
    a = np.asarray(c, dtype=np.float64).reshape(-1)
    if a.size == 1:
        a = np.repeat(a, 3)
    if a.shape != (3,) or not np.all(np.isfinite(a)) or np.any(a < 0) or np.any(a > 1):
        raise ValueError(f"{name} must be a grey level or an RGB triple in [0, 1], got {c!r}")
    return a


def _finish(img: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(np.clip(img, 0.0, 1.0), dtype=np.float32)


def _value_noise(width: int, height: int, rng: np.random.Generator, cells_x: int, cells_y: int):
    """One octave of periodic value noise, (H, W) float64 in [0, 1].

    A (cells_y, cells_x) lattice of uniform random values, interpolated with the quintic fade
    6t^5 - 15t^4 + 10t^3 (C2-continuous); the lattice wraps, so the result tiles.
    """
    lattice = rng.random((cells_y, cells_x))
    # Pixel centres in lattice units.
    gx = (np.arange(width) + 0.5) * (cells_x / width)
    gy = (np.arange(height) + 0.5) * (cells_y / height)
    x0 = np.floor(gx).astype(np.intp)
    y0 = np.floor(gy).astype(np.intp)
    tx, ty = gx - x0, gy - y0
    fx = tx * tx * tx * (tx * (tx * 6 - 15) + 10)
    fy = ty * ty * ty * (ty * (ty * 6 - 15) + 10)
    x0 %= cells_x
    y0 %= cells_y
    x1 = (x0 + 1) % cells_x
    y1 = (y0 + 1) % cells_y
    top = lattice[y0][:, x0] * (1 - fx) + lattice[y0][:, x1] * fx  # (H, W)
    bot = lattice[y1][:, x0] * (1 - fx) + lattice[y1][:, x1] * fx
    return top * (1 - fy)[:, None] + bot * fy[:, None]


def _fractal(width, height, rng, octaves, base_cells, persistence, lacunarity=2):
    """Sum of ``octaves`` value-noise octaves, normalised to [0, 1] by the amplitude sum."""
    total = np.zeros((height, width))
    amp_sum = 0.0
    amp = 1.0
    for k in range(octaves):
        cells = base_cells * lacunarity**k
        cx = max(1, int(round(cells * width / max(width, height))))
        cy = max(1, int(round(cells * height / max(width, height))))
        total += amp * _value_noise(width, height, rng, cx, cy)
        amp_sum += amp
        amp *= persistence
    return total / amp_sum


def _ramp(t: np.ndarray, colors) -> np.ndarray:
    """Map t in [0, 1] (H, W) through a piecewise-linear colour ramp of >= 2 evenly spaced stops."""
    stops = np.stack([_color(c, "colors[i]") for c in colors])  # (K, 3)
    if len(stops) < 2:
        raise ValueError("colors needs at least 2 colour stops")
    xs = np.linspace(0.0, 1.0, len(stops))
    return np.stack([np.interp(t, xs, stops[:, ch]) for ch in range(3)], axis=-1)


# --- textures ----------------------------------------------------------------------------------


def checkerboard(squares_u: int = 8, squares_v: int = 8,
                 colors: tuple[Color, Color] = ((0.8, 0.8, 0.8), (0.05, 0.05, 0.05)),
                 px_per_square: int = 32) -> np.ndarray:
    """Checkerboard of ``squares_u`` columns by ``squares_v`` rows of squares.

    Square (row i, column j) gets ``colors[(i + j) % 2]``, so the top-left square is colors[0].
    Square edges fall exactly on pixel edges. Returns (squares_v * px_per_square,
    squares_u * px_per_square, 3) float32 linear reflectance.
    """
    for name, n in (("squares_u", squares_u), ("squares_v", squares_v),
                    ("px_per_square", px_per_square)):
        if int(n) != n or n < 1:
            raise ValueError(f"{name} must be a positive integer, got {n!r}")
    if len(colors) != 2:
        raise ValueError(f"colors must be two colours, got {colors!r}")
    c = np.stack([_color(colors[0], "colors[0]"), _color(colors[1], "colors[1]")])
    p = int(px_per_square)
    row_sq = np.arange(int(squares_v) * p) // p
    col_sq = np.arange(int(squares_u) * p) // p
    parity = (row_sq[:, None] + col_sq[None, :]) % 2  # (H, W)
    return _finish(c[parity])


def noise(size_px=256, seed: int = 0, octaves: int = 5, base_cells: int = 4,
          persistence: float = 0.5,
          colors=((0.05, 0.05, 0.05), (0.9, 0.9, 0.9))) -> np.ndarray:
    """Multi-scale (fractal value) noise through a colour ramp; tiles seamlessly.

    Args:
        size_px: int or (width, height).
        octaves: number of octaves; octave k has ``base_cells * 2**k`` lattice cells along the
            longer side, amplitude ``persistence**k``.
        base_cells: lattice cells of the coarsest octave along the longer side.
        persistence: amplitude ratio between successive octaves, in (0, 1].
        colors: >= 2 linear RGB stops, evenly spaced over the noise value range; the noise is
            stretched so that its minimum maps to colors[0] and its maximum to colors[-1].
    """
    w, h = _size_wh(size_px)
    if int(octaves) != octaves or octaves < 1:
        raise ValueError(f"octaves must be a positive integer, got {octaves!r}")
    if int(base_cells) != base_cells or base_cells < 1:
        raise ValueError(f"base_cells must be a positive integer, got {base_cells!r}")
    if not 0 < persistence <= 1:
        raise ValueError(f"persistence must be in (0, 1], got {persistence!r}")
    rng = np.random.default_rng(seed)
    t = _fractal(w, h, rng, int(octaves), int(base_cells), float(persistence))
    lo, hi = t.min(), t.max()
    t = (t - lo) / (hi - lo) if hi > lo else np.zeros_like(t)
    return _finish(_ramp(t, colors))


def _splat_discs(width, height, cx, cy, radius, values, combine):
    """Rasterise antialiased discs onto a periodic (H, W) canvas, vectorised over discs.

    Each disc i covers pixel centres with coverage clip(radius_i + 0.5 - distance, 0, 1) (a
    one-pixel linear ramp: the covered area equals pi r^2 to within O(1/r)). ``combine='max'``
    stores max(coverage * values_i) per pixel; ``combine='index'`` stores, per pixel, the largest disc
    index i whose coverage is >= 0.5 (-1 where none), i.e. the last-drawn disc is on top.
    Discs are processed in groups of similar radius so the per-disc pixel window stays small.
    """
    out = np.full(height * width, -1 if combine == "index" else 0.0,
                  dtype=np.int64 if combine == "index" else np.float64)
    order = np.argsort(radius, kind="stable")
    # Groups whose window side doubles: total work ~ sum of disc areas, not n * max area.
    r_sorted = radius[order]
    bounds = [0]
    while bounds[-1] < len(order):
        start = bounds[-1]
        limit = max(2.0 * r_sorted[start], r_sorted[start] + 1.0)
        stop = int(np.searchsorted(r_sorted, limit, side="right"))
        stop = max(stop, start + 1)
        # Cap the number of (disc, pixel) pairs per chunk (~4M) to bound memory.
        win = 2 * int(np.ceil(r_sorted[stop - 1] + 1.0)) + 1
        stop = min(stop, start + max(1, 4_000_000 // (win * win)))
        bounds.append(stop)
    for start, stop in zip(bounds[:-1], bounds[1:]):
        idx = order[start:stop]
        half = int(np.ceil(radius[idx].max() + 1.0))
        off = np.arange(-half, half + 1)
        # Pixel centres near each disc centre (pixel (i, j) has its centre at (j + 0.5, i + 0.5)).
        px = np.floor(cx[idx])[:, None] + off[None, :]  # (n, k)
        py = np.floor(cy[idx])[:, None] + off[None, :]
        dx = (px + 0.5 - cx[idx][:, None])[:, None, :]  # (n, 1, k)
        dy = (py + 0.5 - cy[idx][:, None])[:, :, None]  # (n, k, 1)
        cov = np.clip(radius[idx][:, None, None] + 0.5 - np.sqrt(dx * dx + dy * dy), 0.0, 1.0)
        flat = ((py.astype(np.int64) % height)[:, :, None] * width
                + (px.astype(np.int64) % width)[:, None, :])  # (n, k, k)
        if combine == "index":
            hit = cov >= 0.5
            ids = np.broadcast_to(idx[:, None, None], hit.shape)
            np.maximum.at(out, flat[hit], ids[hit])
        else:
            np.maximum.at(out, flat.ravel(), (cov * values[idx][:, None, None]).ravel())
    return out.reshape(height, width)


def speckle(size_px=512, seed: int = 0, density: float = 0.5, dot_radius_px: float = 2.0,
            background: Color = (0.9, 0.9, 0.9), foreground: Color = (0.02, 0.02, 0.02)
            ) -> np.ndarray:
    """Random-dot speckle for stereo matching: dark antialiased discs on a light ground.

    Dot centres are a uniform (Poisson-like) point set with a fixed count; discs are isotropic and
    all of radius ``dot_radius_px``. ``density`` is the expected FRACTION OF AREA covered by dots:
    overlapping discs of area a at a rate lam per pixel cover 1 - exp(-lam a), so
    ``n_dots = round(-ln(1 - density) / (pi r^2) * W * H)``. The pattern wraps (tiles).

    Returns (H, W, 3) float32; pixel = background + coverage * (foreground - background).
    """
    w, h = _size_wh(size_px)
    if not 0 < density < 1:
        raise ValueError(f"density must be in (0, 1), got {density!r}")
    if not dot_radius_px >= 0.5:
        raise ValueError(f"dot_radius_px must be >= 0.5, got {dot_radius_px!r}")
    bg, fg = _color(background, "background"), _color(foreground, "foreground")
    rng = np.random.default_rng(seed)
    r = float(dot_radius_px)
    n = int(round(-np.log1p(-density) / (np.pi * r * r) * w * h))
    cx = rng.random(n) * w
    cy = rng.random(n) * h
    cov = _splat_discs(w, h, cx, cy, np.full(n, r), np.ones(n), "max")  # (H, W)
    return _finish(bg + cov[..., None] * (fg - bg))


def natural(size_px=512, seed: int = 0, min_radius_px: float = 2.0,
            max_radius_px: float | None = None, alpha: float = 3.0, fine_noise: float = 0.03,
            supersample: int = 2) -> np.ndarray:
    """A natural-looking, feature-rich texture: the "dead leaves" model plus fine noise.

    Dead leaves (Matheron; Lee, Mumford & Huang 2001, "Occlusion models for natural images"): opaque
    discs with random centres, random colours and radii drawn from p(r) ~ r^-alpha on
    [min_radius_px, max_radius_px] fall on top of each other until the plane is covered. With
    alpha = 3 the result is scale-invariant, like natural images, and full of corners and blobs
    at every scale (good for SIFT/ORB-style matching). The pattern wraps (tiles).

    Args:
        size_px: int or (width, height).
        min_radius_px, max_radius_px: radius range in output pixels; max defaults to a quarter of
            the shorter side.
        alpha: power-law exponent of the radius density (> 1).
        fine_noise: amplitude (linear reflectance) of an added fine-grained value noise.
        supersample: discs are drawn at this many samples per pixel per axis and box-filtered,
            which antialiases their edges.
    """
    w, h = _size_wh(size_px)
    if max_radius_px is None:
        max_radius_px = min(w, h) / 4
    if not 0.5 <= min_radius_px < max_radius_px:
        raise ValueError(f"need 0.5 <= min_radius_px < max_radius_px, got {min_radius_px!r}, "
                         f"{max_radius_px!r}")
    if not alpha > 1:
        raise ValueError(f"alpha must be > 1, got {alpha!r}")
    if int(supersample) != supersample or not 1 <= supersample <= 4:
        raise ValueError(f"supersample must be an integer in 1..4, got {supersample!r}")
    if not 0 <= fine_noise <= 0.5:
        raise ValueError(f"fine_noise must be in [0, 0.5], got {fine_noise!r}")
    s = int(supersample)
    rng = np.random.default_rng(seed)
    W, H = w * s, h * s
    r0, r1 = min_radius_px * s, max_radius_px * s
    # Expected covered area (counting overlaps) per disc under p(r) ~ r^-alpha, via the moments;
    # drawing discs worth ~8 image areas leaves ~exp(-8) = 0.03% uncovered, filled by a background.
    a1 = 1.0 - alpha
    a3 = 3.0 - alpha
    norm = (r1**a1 - r0**a1) / a1
    mean_r2 = ((r1**a3 - r0**a3) / a3 if a3 != 0 else np.log(r1 / r0)) / norm
    n = int(np.ceil(8.0 * W * H / (np.pi * mean_r2)))
    u = rng.random(n)
    radius = (r0**a1 + u * (r1**a1 - r0**a1)) ** (1.0 / a1)  # inverse-CDF power law
    cx = rng.random(n) * W
    cy = rng.random(n) * H
    # Colours: a random grey level times a mildly saturated random tint, in linear reflectance.
    grey = rng.uniform(0.02, 0.85, n)
    tint = rng.uniform(0.6, 1.0, (n, 3))
    colors = grey[:, None] * tint / tint.max(axis=1, keepdims=True)
    background = rng.uniform(0.02, 0.85, 3)
    top = _splat_discs(W, H, cx, cy, radius, None, "index")  # (H*s, W*s), -1 = uncovered
    img = np.where(top[..., None] >= 0, colors[np.maximum(top, 0)], background)
    if s > 1:
        img = img.reshape(h, s, w, s, 3).mean(axis=(1, 3))
    if fine_noise > 0:
        cells = max(2, min(w, h) // 2)
        t = _fractal(w, h, rng, 2, cells, 0.5)
        img = img + fine_noise * (2.0 * t[..., None] - 1.0)
    return _finish(img)


# --- registry for the spec layer ----------------------------------------------------------------

_SEEDED = {"noise", "speckle", "natural"}

#: kind name -> builder. Seeded kinds take the seed from :func:`make_texture`'s ``seed`` argument.
TEXTURE_KINDS: dict[str, Callable[..., np.ndarray]] = {
    "checkerboard": checkerboard,
    "noise": noise,
    "speckle": speckle,
    "natural": natural,
    "image": load_image,
}


def texture_params(kind: str) -> tuple[str, ...]:
    """The parameter names ``kind`` accepts in :func:`make_texture` (``seed`` excluded)."""
    if kind not in TEXTURE_KINDS:
        raise ValueError(f"unknown texture kind {kind!r}; known kinds: {sorted(TEXTURE_KINDS)}")
    names = inspect.signature(TEXTURE_KINDS[kind]).parameters
    return tuple(n for n in names if n != "seed")


def check_texture_size(kind: str, params) -> tuple[int, int]:
    """(width, height) in texels the procedural texture ``kind`` would have with ``params``,
    computed without making it; ValueError when it is not a positive size or exceeds
    MAX_TEXTURE_PIXELS (so the spec is refused before anything is allocated)."""
    defaults = {n: p.default for n, p in inspect.signature(TEXTURE_KINDS[kind]).parameters.items()}
    get = lambda n: params.get(n, defaults.get(n))  # noqa: E731
    if kind == "checkerboard":
        try:
            w, h = (int(get(a)) * int(get("px_per_square")) for a in ("squares_u", "squares_v"))
        except (TypeError, ValueError, OverflowError):
            raise ValueError("squares_u, squares_v and px_per_square must be whole numbers") from None
        return _size_wh((w, h))
    if "size_px" not in defaults:
        return (0, 0)
    w, h = _size_wh(get("size_px"))
    ss = get("supersample") if "supersample" in defaults else 1
    if isinstance(ss, (int, float)) and ss > 1 and w * h * ss * ss > MAX_TEXTURE_PIXELS:
        raise ValueError(f"size_px {w} x {h} with supersample {ss} is more than {MAX_TEXTURE_PIXELS:,} pixels")
    return w, h


def make_texture(kind: str, params: dict | None = None, seed: int = 0) -> np.ndarray:
    """Build a texture by kind name: 'checkerboard', 'noise', 'speckle', 'natural' or 'image'.

    ``params`` are the keyword arguments of the builder (for 'image': ``path``); ``seed`` is used by
    the random kinds and ignored by the others. Raises ValueError naming an unknown kind, an
    unknown parameter (with the accepted ones), or an invalid value.
    """
    allowed = texture_params(kind)
    params = dict(params or {})
    unknown = sorted(set(params) - set(allowed))
    if unknown:
        raise ValueError(f"texture kind {kind!r}: unknown parameter(s) {unknown}; "
                         f"accepted: {list(allowed)}")
    builder = TEXTURE_KINDS[kind]
    try:
        if kind in _SEEDED:
            return builder(seed=seed, **params)
        return builder(**params)
    except TypeError as e:  # e.g. a required parameter is missing
        raise ValueError(f"texture kind {kind!r}: {e}") from None
