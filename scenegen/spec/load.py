"""YAML text -> :class:`~scenegen.spec.model.SceneSpec`, with validation.

One function per section and per kind of thing. Every failure is a
:class:`~scenegen.errors.SpecError` with file, line and field path. After parsing, the view sets
are resolved once (:func:`scenegen.spec.views.resolve_views`) so that degenerate placements are
reported at validation time too.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from scenegen.geometry.rotation import matrix_from_quat_wxyz
from scenegen.errors import SpecError
from scenegen.geometry import seeds
from scenegen.geometry.pose import Rigid3, look_at
from scenegen.geometry.rotation import rotation_from_euler_deg
from scenegen.spec import model as m
from scenegen.located_yaml import Document, Fields, Node, suggest

TOP_LEVEL_KEYS = ("name", "description", "seed", "render", "materials", "objects", "lights",
                  "cameras", "rigs", "views", "crossview", "variation")
_SEED_MAX = 2**32 - 1
_ID_MAX = 2**31 - 1


def load_spec(path) -> m.SceneSpec:
    """Read and validate a YAML scene spec. Relative file paths in it resolve against its folder."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as e:
        raise SpecError(f"cannot read the spec file: {e.strerror or e}", file=str(path)) from None
    return parse_spec(text, file=str(path), base_dir=p.resolve().parent)


def parse_spec(text: str, file: str = "<string>", base_dir=None) -> m.SceneSpec:
    """Parse and validate spec text. ``base_dir`` (default: the current directory, or the folder
    of ``file`` when it exists) is where relative file paths resolve."""
    if base_dir is None:
        fp = Path(file)
        base_dir = fp.resolve().parent if fp.is_file() else Path.cwd()
    doc = Document(text, file, Path(base_dir))
    return _Parser(doc).scene()


def derive_seed(scene_seed: int, field_path: str) -> int:
    """Default seed of a seeded thing: stable, differs between field paths (0 .. 2**32 - 1)."""
    return seeds.seed32(scene_seed, field_path)


class _Parser:
    def __init__(self, doc: Document):
        self.doc = doc
        self.seed = 0
        self.warnings: list[str] = []

    def warn(self, node: Node, message: str):
        self.warnings.append(str(SpecError.at(node.where, message)))

    # -- top level --------------------------------------------------------------------------
    def scene(self) -> m.SceneSpec:
        root = self.doc.root
        if root.node is None:
            raise SpecError("expected a mapping at the top level (keys: "
                            f"{', '.join(TOP_LEVEL_KEYS)}), got an empty document",
                            file=self.doc.file, line=1)
        f = root.as_mapping("a mapping at the top level (keys: name, objects, cameras, views, ...)")
        f.check(optional=TOP_LEVEL_KEYS)
        if self.doc.file.startswith("<"):
            default_name = "scene"
        else:
            default_name = Path(self.doc.file).stem
        name = f.get("name").as_name("a scene name") if "name" in f else default_name
        description = f.get("description").as_str() if "description" in f else ""
        self.seed = f.int("seed", 0, lo=0, hi=_SEED_MAX)
        render = self.render(f.get("render"))
        self.render_bit_depth = render.bit_depth  # default output bits of a camera's imaging chain
        materials = self.named_section(f, "materials", self.material)
        cameras = self.named_section(f, "cameras", self.camera)
        self.cameras = cameras
        rigs = self.named_section(f, "rigs", self.rig)
        objects = self.list_section(f, "objects", self.object, materials)
        _unique_names(f.get("objects"), objects, "object")
        lights = self.list_section(f, "lights", self.light)
        _unique_names(f.get("lights"), lights, "light")
        self.lights = lights  # named by view sets' `lights:`
        view_sets = self.list_section(f, "views", self.view_set, cameras, rigs)
        crossview = self.crossview(f.get("crossview")) if "crossview" in f else None
        variation = None
        if "variation" in f:  # seeded ranges for --variants (scenegen/spec/variation.py)
            from scenegen.spec.variation import parse_variation

            variation = parse_variation(f.get("variation"), scene_seed=self.seed, objects=objects,
                                        lights=lights, cameras=cameras, derive_seed=derive_seed)
        spec = m.SceneSpec(
            name=name, description=description, seed=self.seed, render=render,
            materials=m.frozen_mapping(materials), objects=tuple(objects), lights=tuple(lights),
            cameras=m.frozen_mapping(cameras), rigs=m.frozen_mapping(rigs),
            view_sets=tuple(view_sets), file=self.doc.file, base_dir=self.doc.base_dir,
            warnings=tuple(self.warnings), crossview=crossview, variation=variation)
        from scenegen.spec.views import resolve_views

        views = resolve_views(spec)  # degenerate placements are errors now, not at render time
        self.check_crossview_pairs(views)
        return spec

    # -- cross-view truth (docs/crossview.md) ------------------------------------------------
    def crossview(self, node: Node) -> m.CrossviewSpec:
        f = node.as_mapping("a crossview section (pairs, flow, stereo, matches, sift, ...)")
        f.check(optional=("pairs", "flow", "stereo", "matches", "sift", "sift_ratio",
                          "sift_inlier_px", "targets"))
        self._crossview_pairs: list = []
        pairs: object = "consecutive"
        pn = f.get("pairs")
        if pn is not None and pn.is_sequence:
            out = []
            for item in pn.items("a list of [view_a, view_b] pairs"):
                names = item.items("a pair [view_a, view_b] of view names")
                if len(names) != 2:
                    raise item.error(f"expected a pair [view_a, view_b] of view names, got "
                                     f"{len(names)} items")
                a, b = (n.as_str("a view name") for n in names)
                if a == b:
                    raise names[1].error(f"a pair needs two different views, got {a!r} twice")
                out.append((a, b))
                self._crossview_pairs.extend(zip((a, b), names))
            if not out:
                raise pn.error("expected at least one pair, got an empty list (use pairs: none)")
            pairs = tuple(out)
        elif pn is not None:
            pairs = pn.as_enum(m.CROSSVIEW_PAIR_MODES, "pair selection (or a list of pairs)")

        def flag(key, default):
            return f.get(key).as_bool() if key in f else default

        matches = None
        if "matches" in f:
            mf = f.get("matches").as_mapping("a match-set mapping (count, sigma_px, ...)").check(
                optional=("count", "sigma_px", "outlier_fraction", "near_miss_fraction",
                          "near_miss_px", "seed"))
            near = (4.0, 16.0)
            if "near_miss_px" in mf:
                near = mf.get("near_miss_px").as_floats(2, "min and max distance, pixels", lo=0.0,
                                                       lo_open=True)
                if near[0] > near[1]:
                    raise mf.get("near_miss_px").error(f"expected min <= max, got {list(near)}")
            seed = mf.int("seed", None, lo=0, hi=_SEED_MAX)
            matches = m.MatchSetSpec(
                count=mf.int("count", 1000, "matches per pair", lo=1),
                sigma_px=mf.float("sigma_px", 0.5, "pixels", lo=0.0),
                outlier_fraction=mf.float("outlier_fraction", 0.2, "fraction", lo=0.0, hi=1.0,
                                          hi_open=True),
                near_miss_fraction=mf.float("near_miss_fraction", 0.5, "fraction", lo=0.0, hi=1.0),
                near_miss_px=near,
                seed=derive_seed(self.seed, f.get("matches").path) if seed is None else seed,
                where=f.get("matches").where)
        return m.CrossviewSpec(
            pairs=pairs, flow=flag("flow", True), stereo=flag("stereo", True), matches=matches,
            sift=flag("sift", False),
            sift_ratio=f.float("sift_ratio", 0.8, "Lowe ratio", lo=0.0, lo_open=True, hi=1.0),
            sift_inlier_px=f.float("sift_inlier_px", 2.0, "pixels", lo=0.0, lo_open=True),
            targets=flag("targets", True), where=node.where)

    def check_crossview_pairs(self, views) -> None:
        """Explicit crossview pairs must name resolved views."""
        names = [v.name for v in views]
        for name, node in getattr(self, "_crossview_pairs", ()):
            if name not in names:
                shown = ", ".join(names[:8]) + (", ..." if len(names) > 8 else "") or "none"
                raise node.error(f"undefined view {name!r}{suggest(name, names)}; views: {shown}")

    def named_section(self, f: Fields, key: str, parse) -> dict:
        node = f.get(key)
        if node is None:
            return {}
        section = node.as_mapping(f"a mapping of names to {key}")
        out = {}
        for name in section.keys():
            section.key_node(name).as_name(f"a {key[:-1]} name")
            out[name] = parse(section.value(name), name)
        return out

    def list_section(self, f: Fields, key: str, parse, *args) -> list:
        node = f.get(key)
        if node is None:
            return []
        return [parse(item, i, *args) for i, item in enumerate(node.items(f"a list of {key}"))]

    # -- render --------------------------------------------------------------------------------
    def render(self, node: Node | None) -> m.RenderSettings:
        if node is None:
            return m.RenderSettings()
        f = node.as_mapping().check(
            optional=("spp", "max_depth", "seed", "variant", "bit_depth", "sampler", "motion_subframes"))
        spp = f.int("spp", 64, "samples per pixel", lo=1)
        max_depth = f.int("max_depth", 6, "path segments, -1 = unbounded", lo=-1)
        if max_depth == 0:
            raise f.get("max_depth").error("expected -1 (unbounded) or a positive integer, got 0")
        sampler = f.get("sampler").as_enum(m.SAMPLERS, "sampler") if "sampler" in f else "ldsampler"
        if (n := m.effective_spp(sampler, spp)) != spp:
            self.warn(f.get("spp") or node, f"spp = {spp}: Mitsuba's {sampler} rounds it up to {n} samples per "
                      "pixel (recorded as render_used.spp_effective)")
        return m.RenderSettings(
            spp=spp, max_depth=max_depth, seed=f.int("seed", 0, lo=0, hi=_SEED_MAX),
            variant=f.get("variant").as_enum(m.RENDER_VARIANTS, "variant") if "variant" in f
            else "auto",
            bit_depth=f.get("bit_depth").as_enum(m.BIT_DEPTHS, "bit depth") if "bit_depth" in f
            else 8,
            sampler=sampler, motion_subframes=f.int("motion_subframes", 8, "sub-frames", lo=1, hi=256),
            where=node.where)

    # -- textures and materials --------------------------------------------------------------
    def texture(self, node: Node) -> m.Texture:
        f = node.as_mapping("a texture (a mapping with 'type')")
        f.check(required=("type",), optional=("path", "params", "seed"))
        kind = f.get("type").as_enum(m.TEXTURE_KINDS, "texture type")
        if kind == "image":
            if "params" in f or "seed" in f:
                bad = "params" if "params" in f else "seed"
                raise f.get(bad).error(f"an image texture takes only 'path', not {bad!r}")
            path, written = f.req("path").as_path(m.IMAGE_SUFFIXES, "image")
            return m.Texture(kind=kind, path=path, path_as_written=written, where=node.where)
        if "path" in f:
            raise f.get("path").error(f"a {kind} texture is procedural and takes no 'path'; "
                                      "use type: image for image files")
        params = {}
        if "params" in f:
            pf = f.get("params").as_mapping("a mapping of texture parameters")
            _check_texture_params(kind, pf)
            params = f.get("params").plain()
        seed = f.int("seed", None, lo=0, hi=_SEED_MAX)
        if seed is None:
            seed = derive_seed(self.seed, node.path)
        return m.Texture(kind=kind, params=_freeze(params), seed=seed, where=node.where)

    def material(self, node: Node, name: str | None) -> m.Material:
        if node.is_null:
            raise node.error("expected a material (a mapping with 'type'), got nothing (null)")
        f = node.as_mapping("a material (a mapping with 'type')")
        if "type" not in f:
            f.check(required=("type",), optional=f.keys())
        kind = f.get("type").as_enum(m.MATERIAL_TYPES, "material type")
        if kind == "conductor":
            f.check(required=("type",), optional=("material", "roughness"))
            cname = "Al"
            if "material" in f:
                cname = f.get("material").as_str("a conductor name")
                if cname not in m.CONDUCTOR_NAMES:
                    raise f.get("material").error(
                        f"unknown conductor {cname!r}{suggest(cname, m.CONDUCTOR_NAMES)}; "
                        "Mitsuba knows e.g. 'Al', 'Ag', 'Au', 'Cu', 'Cr', 'W'")
            return m.ConductorMaterial(name=name, material=cname,
                                       roughness=f.float("roughness", 0.1, "GGX alpha", lo=0.0),
                                       where=node.where)
        extra = ("roughness", "ior") if kind == "plastic" else ()
        f.check(required=("type",), optional=("color", "texture") + extra)
        which = f.one_of(("color", "texture"), required=False)
        color = f.get("color").as_color() if which == "color" else None
        if color is not None and max(color) > 1.0:
            raise f.get("color").error(f"expected reflectance in [0, 1] (linear RGB), got {color}")
        texture = self.texture(f.get("texture")) if which == "texture" else None
        if which is None:
            color = (0.5, 0.5, 0.5)
        if kind == "diffuse":
            return m.DiffuseMaterial(name=name, color=color, texture=texture, where=node.where)
        return m.PlasticMaterial(
            name=name, color=color, texture=texture,
            roughness=f.float("roughness", 0.1, "GGX alpha", lo=0.0),
            ior=f.float("ior", 1.49, "index of refraction", lo=1.0, lo_open=True),
            where=node.where)

    # -- objects -------------------------------------------------------------------------------
    def object(self, node: Node, index: int, materials: dict) -> m.SceneObject:
        f = node.as_mapping("an object (a mapping with 'name' and one of shape, mesh, target)")
        f.check(required=("name",),
                optional=("shape", "mesh", "target", "transform", "material", "instance_id", "motion"))
        name = f.get("name").as_name("an object name")
        which = f.one_of(("shape", "mesh", "target"))
        if which == "shape":
            geometry = self.shape(f.get("shape"))
        elif which == "mesh":
            path, written = f.get("mesh").as_path(m.MESH_SUFFIXES, "mesh")
            geometry = m.Mesh(path=path, path_as_written=written)
        else:
            geometry = self.target(f.get("target"))
        transform = self.transform(f.get("transform")) if "transform" in f else m.Transform()
        mat_node = f.get("material")
        if mat_node is None:
            material = m.DiffuseMaterial(where=node.where)
        elif mat_node.is_mapping:
            material = self.material(mat_node, None)
        else:
            ref = mat_node.as_str("a material name or an inline material mapping")
            if ref not in materials:
                defined = ", ".join(materials) or "none"
                raise mat_node.error(f"undefined material {ref!r}{suggest(ref, materials)}; "
                                     f"defined under materials: {defined}")
            material = materials[ref]
        object_id = index + 1
        instance_id = f.int("instance_id", object_id, lo=1, hi=_ID_MAX)
        return m.SceneObject(name=name, geometry=geometry, transform=transform, material=material,
                             object_id=object_id, instance_id=instance_id,
                             motion=self.motion(f.get("motion")) if "motion" in f else None, where=node.where)

    def shape(self, node: Node) -> m.Shape:
        if not node.is_mapping:
            kind = node.as_enum(m.SHAPE_KINDS, "shape")  # shorthand: `shape: sphere`
            f = None
        else:
            f = node.as_mapping()
            kind = f.req("type").as_enum(m.SHAPE_KINDS, "shape type")
        keys = {
            "plane": ("size",), "box": ("size",), "sphere": ("radius",),
            "cylinder": ("radius", "height"), "torus": ("major_radius", "minor_radius"),
            "blob": ("radius", "amplitude", "frequency", "subdivisions", "seed"),
        }[kind]
        if f is None:
            f = Fields.empty(node)
        else:
            f.check(required=("type",), optional=keys)

        def pos(key, default):
            return f.float(key, default, "metres", lo=0.0, lo_open=True)

        if kind in ("plane", "box"):
            n = 2 if kind == "plane" else 3
            size = f.get("size").as_floats(n, "metres", lo=0.0, lo_open=True) if "size" in f \
                else (1.0,) * n
            return m.Plane(size=size) if kind == "plane" else m.Box(size=size)
        if kind == "sphere":
            return m.Sphere(radius=pos("radius", 0.5))
        if kind == "cylinder":
            return m.Cylinder(radius=pos("radius", 0.5), height=pos("height", 1.0))
        if kind == "torus":
            major, minor = pos("major_radius", 0.5), pos("minor_radius", 0.15)
            if minor >= major:
                bad = f.get("minor_radius") or f.get("major_radius") or node
                raise bad.error(f"expected minor_radius < major_radius (a ring torus), got "
                                f"minor_radius {minor:g} >= major_radius {major:g}")
            return m.Torus(major_radius=major, minor_radius=minor)
        seed = f.int("seed", None, lo=0, hi=_SEED_MAX)
        return m.Blob(radius=pos("radius", 0.5),
                      amplitude=f.float("amplitude", 0.15, "fraction of radius", lo=0.0, hi=1.0,
                                        hi_open=True),
                      frequency=f.float("frequency", 2.0, lo=0.0, lo_open=True),
                      subdivisions=f.int("subdivisions", 5, lo=1, hi=7),
                      seed=derive_seed(self.seed, node.path) if seed is None else seed)

    def target(self, node: Node) -> m.Target:
        f = node.as_mapping("a calibration target (a mapping with 'type')")
        kind = f.req("type").as_enum(m.TARGET_KINDS, "target type")
        pos_m = dict(lo=0.0, lo_open=True)
        if kind == "checkerboard":
            f.check(required=("type", "inner_cols", "inner_rows", "square_m"),
                    optional=("margin_m",))
            square = f.float("square_m", unit="metres", **pos_m)
            return m.CheckerboardTarget(
                inner_cols=f.int("inner_cols", lo=2), inner_rows=f.int("inner_rows", lo=2),
                square_m=square, margin_m=f.float("margin_m", square, "metres", lo=0.0))
        dict_node = f.get("dictionary")
        if kind == "charuco":
            f.check(required=("type", "squares_x", "squares_y", "square_m", "marker_m",
                              "dictionary"), optional=("margin_m",))
            sx, sy = f.int("squares_x", lo=2), f.int("squares_y", lo=2)
            square = f.float("square_m", unit="metres", **pos_m)
            marker = f.float("marker_m", unit="metres", **pos_m)
            if marker >= square:
                raise f.get("marker_m").error(
                    f"expected marker_m < square_m ({square:g}), got {marker:g}")
            dictionary = dict_node.as_enum(tuple(m.ARUCO_DICTIONARIES), "ArUco dictionary")
            needed = sx * sy // 2
            if needed > m.ARUCO_DICTIONARIES[dictionary]:
                raise dict_node.error(f"{dictionary} holds {m.ARUCO_DICTIONARIES[dictionary]} "
                                      f"markers; a {sx}x{sy} ChArUco board needs {needed}")
            return m.CharucoTarget(squares_x=sx, squares_y=sy, square_m=square, marker_m=marker,
                                   dictionary=dictionary,
                                   margin_m=f.float("margin_m", square, "metres", lo=0.0))
        f.check(required=("type", "markers_x", "markers_y", "marker_m", "separation_m",
                          "dictionary"), optional=("first_id", "margin_m"))
        mx, my = f.int("markers_x", lo=1), f.int("markers_y", lo=1)
        sep = f.float("separation_m", unit="metres", **pos_m)
        dictionary = dict_node.as_enum(tuple(m.ARUCO_DICTIONARIES), "ArUco dictionary")
        first = f.int("first_id", 0, lo=0)
        size = m.ARUCO_DICTIONARIES[dictionary]
        if first + mx * my > size:
            raise dict_node.error(f"{dictionary} holds {size} markers; a {mx}x{my} grid from id "
                                  f"{first} needs {first + mx * my}")
        return m.ArucoGridTarget(markers_x=mx, markers_y=my,
                                 marker_m=f.float("marker_m", unit="metres", **pos_m),
                                 separation_m=sep, dictionary=dictionary, first_id=first,
                                 margin_m=f.float("margin_m", sep, "metres", lo=0.0))

    def transform(self, node: Node) -> m.Transform:
        f = node.as_mapping("a transform (translation, rotation_deg or rotation_quat_wxyz, "
                            "order, scale)")
        f.check(optional=("translation", "rotation_deg", "rotation_quat_wxyz", "order", "scale"))
        scale = (1.0, 1.0, 1.0)
        if "scale" in f:
            s = f.get("scale")
            if s.is_sequence:
                scale = s.as_floats(3, "unitless", lo=0.0, lo_open=True)
            else:
                v = s.as_float("unitless, or 3 numbers", lo=0.0, lo_open=True)
                scale = (v, v, v)
        return m.Transform(world_from_object=self.rigid(f), scale=scale)

    def rigid(self, f: Fields) -> Rigid3:
        """translation + rotation_deg (with order) | rotation_quat_wxyz, from checked fields."""
        t = f.vec3("translation", (0.0, 0.0, 0.0))
        which = f.one_of(("rotation_deg", "rotation_quat_wxyz"), required=False)
        if "order" in f and which != "rotation_deg":
            raise f.get("order").error("'order' applies to rotation_deg only")
        R = np.eye(3)
        if which == "rotation_deg":
            angles = f.get("rotation_deg").as_floats(3, "degrees")
            R = rotation_from_euler_deg(angles, self.euler_order(f.get("order")))
        elif which == "rotation_quat_wxyz":
            qn = f.get("rotation_quat_wxyz")
            q = qn.as_floats(4, "quaternion w, x, y, z")
            if np.linalg.norm(q) < 1e-12:
                raise qn.error("expected a non-zero quaternion (w, x, y, z), got all zeros")
            R = matrix_from_quat_wxyz(q)
        return Rigid3(R, t)

    @staticmethod
    def euler_order(node: Node | None) -> str:
        if node is None:
            return "xyz"
        order = node.as_str("an Euler axis order such as 'xyz'")
        ok = (len(order) == 3 and (set(order) <= set("xyz") or set(order) <= set("XYZ"))
              and order[0] != order[1] and order[1] != order[2])
        if not ok:
            raise node.error("expected 3 axes, all lower case (extrinsic, fixed world axes) or all "
                             f"upper case (intrinsic), no axis twice in a row, e.g. 'xyz' or 'ZYX'; "
                             f"got {order!r}")
        return order

    def pose_matrix_or_fields(self, node: Node) -> Rigid3:
        """A pose given as a 4x4 / 3x4 matrix or as translation + rotation."""
        if node.is_sequence:
            rows = node.items()
            if len(rows) not in (3, 4):
                raise node.error(f"expected a 4x4 (or 3x4) matrix as a list of rows, got "
                                 f"{len(rows)} rows")
            T = np.array([r.as_floats(4) for r in rows])
            try:
                return Rigid3.from_matrix(T)
            except ValueError as e:
                raise node.error(f"expected a rigid transform: {e}") from None
        f = node.as_mapping("a pose: a 4x4 matrix, or a mapping with translation and "
                            "rotation_deg or rotation_quat_wxyz")
        f.check(optional=("translation", "rotation_deg", "rotation_quat_wxyz", "order"))
        return self.rigid(f)

    # -- lights --------------------------------------------------------------------------------
    def light(self, node: Node, index: int) -> m.Light:
        f = node.as_mapping("a light (a mapping with 'type')")
        kind = f.req("type").as_enum(m.LIGHT_TYPES, "light type")
        keys = {
            "area": ("size", "radiance", "transform", "position", "look_at", "up"),
            "point": ("position", "intensity"),
            "spot": ("position", "target", "intensity", "cutoff_deg", "beam_width_deg"),
            "constant": ("radiance",),
            "envmap": ("path", "scale", "rotation_z_deg"),
        }[kind]
        required = {"point": ("position", "intensity"),
                    "spot": ("position", "target", "intensity"),
                    "constant": ("radiance",), "envmap": ("path",), "area": ("radiance",)}[kind]
        f.check(required=("type",) + required, optional=("name",) + keys)
        name = f.get("name").as_name("a light name") if "name" in f else f"light{index}"
        w = node.where
        if kind == "point":
            return m.PointLight(name=name, position=f.vec3("position"),
                                intensity=f.get("intensity").as_color("linear RGB, W/sr"), where=w)
        if kind == "constant":
            return m.ConstantLight(name=name, where=w, radiance=f.get("radiance").as_color(
                "linear RGB, W/(m^2 sr)"))
        if kind == "envmap":
            path, written = f.get("path").as_path(m.IMAGE_SUFFIXES, "environment image")
            return m.EnvmapLight(name=name, path=path, path_as_written=written,
                                 scale=f.float("scale", 1.0, lo=0.0),
                                 rotation_z_deg=f.float("rotation_z_deg", 0.0, "degrees"), where=w)
        if kind == "spot":
            cutoff = f.float("cutoff_deg", 20.0, "degrees", lo=0.0, lo_open=True, hi=90.0)
            beam = f.float("beam_width_deg", 0.75 * cutoff, "degrees", lo=0.0, lo_open=True,
                           hi=cutoff)
            pos, tgt = f.vec3("position"), f.vec3("target")
            world_from_light = _aim(pos, tgt, (0.0, 0.0, 1.0), f.get("target"))
            return m.SpotLight(name=name, position=pos, target=tgt,
                               world_from_light=world_from_light,
                               intensity=f.get("intensity").as_color("linear RGB, W/sr"),
                               cutoff_deg=cutoff, beam_width_deg=beam, where=w)
        # area
        size = f.get("size").as_floats(2, "metres", lo=0.0, lo_open=True) if "size" in f \
            else (1.0, 1.0)
        which = f.one_of(("transform", "position"))
        if which == "transform":
            for bad in ("look_at", "up"):
                if bad in f:
                    raise f.get(bad).error(f"{bad!r} goes with 'position', not with 'transform'")
            tf = f.get("transform").as_mapping("a transform (translation, rotation_deg or "
                                               "rotation_quat_wxyz, order)")
            tf.check(optional=("translation", "rotation_deg", "rotation_quat_wxyz", "order"))
            world_from_light = self.rigid(tf)
        else:
            if "look_at" not in f:
                raise f.missing("look_at", " (an area light at 'position' faces 'look_at')")
            up = f.vec3("up", (0.0, 0.0, 1.0), "direction")
            world_from_light = _aim(f.vec3("position"), f.vec3("look_at"), up, f.get("look_at"))
        return m.AreaLight(name=name, size=size, world_from_light=world_from_light,
                           radiance=f.get("radiance").as_color("linear RGB, W/(m^2 sr)"), where=w)

    # -- cameras and rigs ----------------------------------------------------------------------
    def camera(self, node: Node, name: str) -> m.CameraSpec:
        f = node.as_mapping("a camera (a mapping with model, size and fx, fy or fov_deg)")
        f.check(required=("size",),
                optional=("model", "fx", "fy", "cx", "cy", "skew", "fov_deg", "dist", "imaging", "lens",
                          "shutter", "chromatic_aberration"))
        model = f.get("model").as_enum(m.CAMERA_MODELS, "camera model") if "model" in f \
            else "pinhole"
        size_node = f.get("size")
        size = size_node.as_floats(2, "width, height in pixels")
        for item, v in zip(size_node.items(), size):
            if not v.is_integer() or v < 1:
                raise item.error(f"expected a positive whole number of pixels, got {v:g}")
        W, H = int(size[0]), int(size[1])
        if "fov_deg" in f:
            for bad in ("fx", "fy"):
                if bad in f:
                    raise f.get(bad).error(f"give either fov_deg or fx and fy, not both")
            fov = f.float("fov_deg", unit="horizontal field of view, degrees", lo=0.0,
                          lo_open=True, hi=180.0, hi_open=True)
            # As scenegen.geometry.camera.Camera.from_fov: the FoV of the undistorted pinhole.
            fx = fy = (W / 2) / math.tan(math.radians(fov) / 2)
        else:
            if "fx" not in f:
                raise f.missing("fx", " (or give fov_deg)")
            fx = f.float("fx", unit="pixels", lo=0.0, lo_open=True)
            fy = f.float("fy", fx, "pixels", lo=0.0, lo_open=True)
            fov = None
        cx = f.float("cx", (W - 1) / 2, "pixels")
        cy = f.float("cy", (H - 1) / 2, "pixels")
        skew = f.float("skew", 0.0, "pixels")
        allowed = m.DIST_LENGTHS[model]
        dist: tuple[float, ...] = ()
        if "dist" in f:
            dn = f.get("dist")
            if model == "pinhole":
                if dn.is_sequence and not dn.items():
                    dist = ()
                else:
                    raise dn.error("a pinhole camera has no distortion; use model: opencv or "
                                   "fisheye, or remove dist")
            else:
                order = ("k1, k2, p1, p2[, k3[, k4, k5, k6[, s1, s2, s3, s4]]]"
                         if model == "opencv" else "k1, k2, k3, k4")
                dist = dn.as_floats(allowed, f"{model} coefficients {order}")
        elif model != "pinhole":
            dist = (0.0,) * allowed[0]
        cam = m.CameraSpec(name=name, model=model, width=W, height=H, fx=fx, fy=fy, cx=cx, cy=cy,
                           skew=skew, dist=dist, fov_deg=fov, where=node.where,
                           imaging=self.imaging(f.get("imaging"), name) if "imaging" in f else None,
                           optics=self.optics(f, model))
        if not (-0.5 <= cx <= W - 0.5 and -0.5 <= cy <= H - 0.5):
            self.warn(node, f"principal point ({cx:g}, {cy:g}) lies outside the image")
        _check_with_camera_model(cam, f.get("dist") or node)
        return cam

    def rig(self, node: Node, name: str) -> m.Rig:
        f = node.as_mapping("a rig (a mapping with 'type': stereo or multi)")
        kind = f.req("type").as_enum(m.RIG_TYPES, "rig type")
        if kind == "stereo":
            f.check(required=("type", "left", "right", "baseline_m"), optional=("vergence_deg",))
            left, right = (self.camera_ref(f.get(k)) for k in ("left", "right"))
            baseline = f.float("baseline_m", unit="metres", lo=0.0, lo_open=True)
            vergence = f.float("vergence_deg", 0.0, "degrees", lo=0.0, hi=90.0, hi_open=True)
            half = math.radians(vergence) / 2
            members = (
                m.RigMember(name="left", camera=left,
                            rig_from_cam=Rigid3.from_rotvec([0.0, half, 0.0], [0.0, 0.0, 0.0])),
                m.RigMember(name="right", camera=right,
                            rig_from_cam=Rigid3.from_rotvec([0.0, -half, 0.0],
                                                            [baseline, 0.0, 0.0])),
            )
            return m.Rig(name=name, type=kind, members=members, baseline_m=baseline,
                         vergence_deg=vergence, where=node.where)
        f.check(required=("type", "members"))
        members, seen = [], {}
        for item in f.get("members").items("a list of rig members"):
            mf = item.as_mapping("a rig member (camera, name, rig_from_cam)")
            mf.check(required=("camera",), optional=("name", "rig_from_cam"))
            cam = self.camera_ref(mf.get("camera"))
            mname = mf.get("name").as_name("a member name") if "name" in mf else cam
            if mname in seen:
                where = mf.get("name") or mf.get("camera")
                raise where.error(f"duplicate member name {mname!r} in rig {name!r} (first at "
                                  f"line {seen[mname]}); give each member a distinct 'name'")
            seen[mname] = item.line
            rig_from_cam = (self.pose_matrix_or_fields(mf.get("rig_from_cam"))
                            if "rig_from_cam" in mf else Rigid3.identity())
            members.append(m.RigMember(name=mname, camera=cam, rig_from_cam=rig_from_cam))
        if not members:
            raise f.get("members").error("expected at least one rig member, got an empty list")
        return m.Rig(name=name, type=kind, members=tuple(members), where=node.where)

    # -- photometric imaging chain of a camera (docs/image_formation.md) ----------------------
    def imaging(self, node: Node, camera_name: str):
        """``cameras.<name>.imaging``: a preset and/or explicit parameters (explicit keys override
        the preset's); returns a :class:`scenegen.imaging.ImagingParams`."""
        import dataclasses

        from scenegen.imaging import bayer, presets, response, seeds

        f = node.as_mapping("an imaging block (preset, exposure, vignetting, sensor, bayer, ...)")
        f.check(optional=("preset", "exposure", "vignetting", "sensor", "bayer", "demosaic",
                          "white_balance", "response", "gamma", "bit_depth"))
        if "preset" in f:
            name = f.get("preset").as_enum(tuple(presets.PRESETS), "imaging preset")
            p = presets.PRESETS[name]
        else:
            from scenegen.imaging import ImagingParams

            p = ImagingParams()
        pos = dict(lo=0.0, lo_open=True)
        # key -> reader(node) for each sub-block; absent keys keep the preset's value
        blocks = {
            "exposure": {
                "exposure_time_s": lambda n: n.as_float("seconds", **pos),
                "f_number": lambda n: n.as_float("f-number", **pos),
                "lens_transmittance": lambda n: n.as_float("fraction", lo=0.0, lo_open=True, hi=1.0),
                "gain_db": lambda n: n.as_float("dB", lo=-60.0, hi=60.0)},
            "vignetting": {
                "natural_cos4": lambda n: n.as_bool(),
                "coeffs": lambda n: n.as_floats(3, "a1, a2, a3 of 1 + a1 r^2 + a2 r^4 + a3 r^6"),
                "center_px": lambda n: n.as_floats(2, "u, v in pixels")},
            "sensor": {
                "pixel_pitch_um": lambda n: n.as_float("micrometres", **pos),
                "quantum_efficiency": lambda n: n.as_floats(3, "R, G, B fractions", lo=0.0, hi=1.0),
                "wavelengths_nm": lambda n: n.as_floats(3, "R, G, B nanometres", **pos),
                "system_gain_dn_per_e": lambda n: n.as_float("DN per electron", **pos),
                "dark_noise_e": lambda n: n.as_float("electrons", lo=0.0),
                "dark_current_e_per_s": lambda n: n.as_float("electrons per second", lo=0.0),
                "saturation_capacity_e": lambda n: n.as_float("electrons", **pos),
                "prnu_percent": lambda n: n.as_float("percent", lo=0.0, hi=100.0),
                "dsnu_e": lambda n: n.as_float("electrons", lo=0.0),
                "black_level_dn": lambda n: n.as_int("DN", lo=0),
                "adc_bits": lambda n: n.as_int("bits", lo=1, hi=16),
                "temporal_noise": lambda n: n.as_bool(),
                "fixed_pattern_seed": lambda n: n.as_int(lo=0, hi=_SEED_MAX)},
        }
        parts = {}
        for block, readers in blocks.items():
            base = getattr(p, block)
            if block in f:
                bf = f.get(block).as_mapping(f"a mapping of {block} parameters").check(
                    optional=tuple(readers))
                base = dataclasses.replace(base, **{k: r(bf.get(k)) for k, r in readers.items()
                                                    if k in bf})
            parts[block] = base
        sensor = parts["sensor"]
        sf = f.get("sensor").as_mapping() if "sensor" in f else None
        if sf is None or "fixed_pattern_seed" not in sf:  # PRNU / DSNU fixed per camera name
            sensor = dataclasses.replace(sensor,
                                         fixed_pattern_seed=seeds.fixed_pattern_seed_for(camera_name))
        if sensor.black_level_dn >= sensor.white_level_dn:
            where = (sf.get("black_level_dn") or sf.get("adc_bits")) if sf is not None else None
            raise (where or node).error(f"expected black_level_dn < 2^adc_bits - 1 = "
                                        f"{sensor.white_level_dn}, got {sensor.black_level_dn}")
        pattern = p.bayer
        if "bayer" in f:
            pattern = f.get("bayer").as_enum(bayer.PATTERNS + ("none",), "Bayer pattern")
            pattern = None if pattern == "none" else pattern
        wb = p.white_balance
        if "white_balance" in f:
            wn = f.get("white_balance")
            if wn.is_sequence:
                wb = wn.as_floats(3, "R, G, B gains", lo=0.0, lo_open=True)
            else:
                wn.as_enum(("auto",), "white balance: 3 gains or auto")
                wb = None  # auto: equal-radiance white comes out neutral
        return dataclasses.replace(
            p, exposure=parts["exposure"], vignetting=parts["vignetting"], sensor=sensor,
            bayer=pattern, white_balance=wb,
            demosaic=f.get("demosaic").as_enum(bayer.DEMOSAIC_METHODS, "demosaic method")
            if "demosaic" in f else p.demosaic,
            response=f.get("response").as_enum(response.RESPONSES, "camera response")
            if "response" in f else p.response,
            gamma=f.float("gamma", p.gamma, "exponent", lo=0.0, lo_open=True),
            bit_depth=f.get("bit_depth").as_enum(m.BIT_DEPTHS, "bit depth") if "bit_depth" in f
            else self.render_bit_depth)

    def camera_ref(self, node: Node) -> str:
        ref = node.as_str("a camera name")
        if ref not in self.cameras:
            defined = ", ".join(self.cameras) or "none"
            raise node.error(f"undefined camera {ref!r}{suggest(ref, self.cameras)}; "
                             f"defined under cameras: {defined}")
        return ref

    # -- views ---------------------------------------------------------------------------------
    def view_set(self, node: Node, index: int, cameras: dict, rigs: dict) -> m.ViewSet:
        f = node.as_mapping("a view set (camera or rig, and one of orbit, look_at, poses, "
                            "random, path)")
        placements = ("orbit", "look_at", "poses", "random", "path")
        f.check(optional=("name", "camera", "rig", "motion", "lights") + placements)
        name = f.get("name").as_name("a view set name") if "name" in f else None
        who = f.one_of(("camera", "rig"))
        camera = rig = None
        if who == "camera":
            camera = self.camera_ref(f.get("camera"))
        else:
            rn = f.get("rig")
            rig = rn.as_str("a rig name")
            if rig not in rigs:
                defined = ", ".join(rigs) or "none"
                raise rn.error(f"undefined rig {rig!r}{suggest(rig, rigs)}; defined under "
                               f"rigs: {defined}")
        kind = f.one_of(placements)
        pn = f.get(kind)
        parse = {"orbit": self.orbit, "look_at": self.look_at_list, "poses": self.poses,
                 "random": self.random, "path": self.path}[kind]
        placement = parse(pn, "rig" if rig else "cam")
        return m.ViewSet(name=name, camera=camera, rig=rig, placement=placement,
                         motion=self.motion(f.get("motion")) if "motion" in f else None,
                         lights=self.view_lights(f.get("lights")) if "lights" in f else None,
                         where=node.where)

    def view_lights(self, node: Node):
        """A view set's ``lights``: a list of names (those at their spec power, the others off)
        or a mapping name -> factor >= 0 (unnamed lights off). Returns every spec light, in
        spec order, with its factor."""
        names = [light.name for light in self.lights]
        if not names:
            raise node.error("the spec defines no lights (add a 'lights:' section); 'lights' on a "
                             "view set switches and scales the spec's lights")

        def known(name_node: Node, name: str) -> str:
            if name not in names:
                raise name_node.error(f"undefined light {name!r}{suggest(name, names)}; "
                                      f"defined under lights: {', '.join(names)}")
            return name

        given: dict[str, float] = {}
        if node.is_sequence:
            first: dict[str, int | None] = {}
            for item in node.items():
                name = known(item, item.as_str("a light name"))
                if name in first:
                    raise item.error(f"duplicate light {name!r} (first at line {first[name]})")
                first[name] = item.line
                given[name] = 1.0
        elif node.is_mapping:
            f = node.as_mapping()
            for name in f.keys():
                known(f.key_node(name), name)
                given[name] = f.value(name).as_float("factor on the light's spec power", lo=0.0)
        else:
            raise node.error("expected a list of light names (on at their spec power, the others "
                             "off) or a mapping of light names to factors >= 0, got "
                             f"{node.describe()}")
        if not given:
            raise node.error("expected at least one light (an empty list or mapping would turn "
                             "every light off; give {name: 0} to do that on purpose)")
        return m.frozen_mapping({name: given.get(name, 0.0) for name in names})

    # -- lens and time effects (scenegen/optics.py, docs/image_formation.md) -------------------
    def optics(self, f, model: str):
        """``lens``, ``shutter`` and ``chromatic_aberration`` of a camera, or None."""
        from scenegen.geometry import optics as o

        if not any(k in f for k in ("lens", "shutter", "chromatic_aberration")):
            return None
        lens = shutter = ca = None
        if "lens" in f:
            if model == "fisheye":
                raise f.get("lens").error("the thin lens is for perspective models (pinhole, opencv); "
                                          "a fisheye has no single focus plane")
            lf = f.get("lens").as_mapping("a thin lens (f_number, focus_distance_m, pixel_pitch_um)").check(
                required=("f_number", "focus_distance_m", "pixel_pitch_um"))
            lens = o.ThinLens(f_number=lf.float("f_number", unit="unitless", lo=0.0, lo_open=True),
                              focus_distance_m=lf.float("focus_distance_m", unit="metres", lo=0.0, lo_open=True),
                              pixel_pitch_um=lf.float("pixel_pitch_um", unit="micrometres", lo=0.0, lo_open=True))
        if "shutter" in f:
            sf = f.get("shutter").as_mapping("a shutter (exposure_s, rolling_readout_s)").check(
                optional=("exposure_s", "rolling_readout_s"))
            shutter = o.Shutter(exposure_s=sf.float("exposure_s", 0.0, "seconds", lo=0.0),
                                rolling_readout_s=sf.float("rolling_readout_s", 0.0, "seconds", lo=0.0))
        if "chromatic_aberration" in f:
            cf = f.get("chromatic_aberration").as_mapping(
                "per-channel focal scales (red_focal_scale, blue_focal_scale)").check(
                optional=("red_focal_scale", "blue_focal_scale"))
            ca = o.ChromaticAberration(
                red_focal_scale=cf.float("red_focal_scale", 1.0, "unitless", lo=0.5, hi=2.0),
                blue_focal_scale=cf.float("blue_focal_scale", 1.0, "unitless", lo=0.5, hi=2.0))
        return o.Optics(lens=lens, shutter=shutter, chromatic_aberration=ca)

    def motion(self, node: Node):
        """Constant linear (m/s) and angular (deg/s, rotation vector) velocities."""
        from scenegen.geometry.optics import Motion

        f = node.as_mapping("a motion (linear_velocity_mps, angular_velocity_deg_s)").check(
            optional=("linear_velocity_mps", "angular_velocity_deg_s"))
        return Motion(linear_velocity_mps=f.vec3("linear_velocity_mps", (0.0, 0.0, 0.0), "metres / second"),
                      angular_velocity_deg_s=f.vec3("angular_velocity_deg_s", (0.0, 0.0, 0.0), "degrees / second"))

    def orbit(self, node: Node, frame: str) -> m.Orbit:
        f = node.as_mapping("an orbit (center, radius_m, elevations_deg, count)").check(
            required=("radius_m", "count"),
            optional=("center", "elevations_deg", "start_azimuth_deg"))
        elevations = (30.0,)
        if "elevations_deg" in f:
            elevations = f.get("elevations_deg").as_floats(None, "degrees", lo=-90.0,
                                                           lo_open=True, hi=90.0)
            for item, e in zip(f.get("elevations_deg").items(), elevations):
                if abs(e) >= 90.0:
                    raise item.error(f"expected an elevation strictly between -90 and 90 degrees "
                                     f"(the view would be parallel to up), got {e:g}")
        return m.Orbit(center=f.vec3("center", (0.0, 0.0, 0.0)),
                       radius_m=f.float("radius_m", unit="metres", lo=0.0, lo_open=True),
                       elevations_deg=elevations, count=f.int("count", lo=1),
                       start_azimuth_deg=f.float("start_azimuth_deg", 0.0, "degrees"))

    def look_at_list(self, node: Node, frame: str) -> m.LookAtList:
        entries = []
        for item in node.items("a list of {eye, target, up} mappings"):
            f = item.as_mapping("a mapping with eye, target and optionally up").check(
                required=("eye", "target"), optional=("up",))
            entry = m.LookAt(eye=f.vec3("eye"), target=f.vec3("target"),
                             up=f.vec3("up", (0.0, 0.0, 1.0), "direction"))
            try:
                look_at(entry.eye, entry.target, entry.up)
            except ValueError as e:
                raise item.error(f"cannot look from {list(entry.eye)} at {list(entry.target)} "
                                 f"with up {list(entry.up)}: {e}") from None
            entries.append(entry)
        if not entries:
            raise node.error("expected at least one {eye, target} entry, got an empty list")
        return m.LookAtList(entries=tuple(entries))

    def poses(self, node: Node, frame: str) -> m.PoseList:
        fwd, inv = f"world_from_{frame}", f"{frame}_from_world"
        other = "rig" if frame == "cam" else "cam"
        out = []
        for item in node.items(f"a list of poses ({fwd} or {inv})"):
            f = item.as_mapping(f"a mapping with {fwd} or {inv}")
            wrong = [k for k in f.keys() if k in (f"world_from_{other}", f"{other}_from_world")]
            if wrong:
                whose = "a rig" if frame == "rig" else "a camera"
                raise f.key_node(wrong[0]).error(
                    f"this view set places {whose}: use {fwd} or {inv}")
            f.check(optional=(fwd, inv))
            key = f.one_of((fwd, inv))
            pose = self.pose_matrix_or_fields(f.get(key))
            out.append(pose if key == fwd else pose.inverse())
        if not out:
            raise node.error("expected at least one pose, got an empty list")
        return m.PoseList(world_from_cam=tuple(out))

    def random(self, node: Node, frame: str) -> m.RandomPoses:
        f = node.as_mapping("random views (count, eye_box, target or target_box)").check(
            required=("count", "eye_box"),
            optional=("seed", "target", "target_box", "up", "min_distance_m"))
        eye_min, eye_max = self.box(f.get("eye_box"))
        which = f.one_of(("target", "target_box"))
        if which == "target":
            t_min = t_max = f.vec3("target")
        else:
            t_min, t_max = self.box(f.get("target_box"))
        seed = f.int("seed", None, lo=0, hi=_SEED_MAX)
        return m.RandomPoses(count=f.int("count", lo=1),
                             seed=derive_seed(self.seed, node.path) if seed is None else seed,
                             eye_min=eye_min, eye_max=eye_max, target_min=t_min, target_max=t_max,
                             up=f.vec3("up", (0.0, 0.0, 1.0), "direction"),
                             min_distance_m=f.float("min_distance_m", 0.0, "metres", lo=0.0))

    def box(self, node: Node):
        f = node.as_mapping("a box {min: [x, y, z], max: [x, y, z]}").check(
            required=("min", "max"))
        lo, hi = f.vec3("min"), f.vec3("max")
        if any(a > b for a, b in zip(lo, hi)):
            raise f.get("max").error(f"expected max >= min on every axis, got min {list(lo)} and "
                                     f"max {list(hi)}")
        return lo, hi

    def path(self, node: Node, frame: str):
        f = node.as_mapping("a path (line or circle, count, target, up)")
        f.check(required=("count",), optional=("line", "circle", "target", "up"))
        which = f.one_of(("line", "circle"))
        up = f.vec3("up", (0.0, 0.0, 1.0), "direction")
        if which == "line":
            lf = f.get("line").as_mapping("a line {from, to}").check(required=("from", "to"))
            if "target" not in f:
                raise f.missing("target", " (a line path looks at a fixed target)")
            return m.LinePath(start=lf.vec3("from"), end=lf.vec3("to"), count=f.int("count", lo=1),
                              target=f.vec3("target"), up=up)
        cf = f.get("circle").as_mapping("a circle {center, radius_m, height_m}").check(
            required=("radius_m",), optional=("center", "height_m", "start_azimuth_deg"))
        center = cf.vec3("center", (0.0, 0.0, 0.0))
        return m.CirclePath(center=center,
                            radius_m=cf.float("radius_m", unit="metres", lo=0.0, lo_open=True),
                            height_m=cf.float("height_m", 0.0, "metres"),
                            count=f.int("count", lo=1),
                            start_azimuth_deg=cf.float("start_azimuth_deg", 0.0, "degrees"),
                            target=f.vec3("target", center), up=up)


def _aim(position, target, up, node: Node) -> Rigid3:
    """world_from_light with +z from position toward target; another up if up is parallel."""
    try:
        return look_at(position, target, up)
    except ValueError as e:
        if "parallel" not in str(e):
            raise node.error(f"expected a point different from the position: {e}") from None
    return look_at(position, target, (0.0, 1.0, 0.0))


def _unique_names(section: Node | None, things, what: str):
    seen: dict[str, int | None] = {}
    for i, thing in enumerate(things):
        item = section.items()[i]
        name_node = item.as_mapping().get("name") or item
        if thing.name in seen:
            raise name_node.error(f"duplicate {what} name {thing.name!r} (first at line "
                                  f"{seen[thing.name]})")
        seen[thing.name] = name_node.line


def _freeze(value):
    if isinstance(value, dict):
        return m.frozen_mapping({k: _freeze(v) for k, v in value.items()})
    if isinstance(value, list):
        return tuple(_freeze(v) for v in value)
    return value


def _check_texture_params(kind: str, params: Fields):
    """Parameter names against scenegen.assets.textures (when present); values are its business."""
    try:
        from scenegen.assets.textures import texture_params
    except ModuleNotFoundError as e:
        if e.name == "scenegen.assets.textures":
            return
        raise
    params.check(optional=texture_params(kind))


def _check_with_camera_model(cam: m.CameraSpec, node: Node):
    """Ask scenegen.geometry.camera (when present) whether the camera can exist (e.g. a distortion that
    folds over inside the image); its ValueError becomes a SpecError at the camera."""
    try:
        import scenegen.geometry.camera  # noqa: F401
    except ModuleNotFoundError as e:
        if e.name == "scenegen.geometry.camera":
            return
        raise
    try:
        cam.to_camera()
    except ValueError as e:
        raise node.error(f"impossible camera: {e}") from None


__all__ = ["load_spec", "parse_spec", "derive_seed", "TOP_LEVEL_KEYS"]
