"""`placement: {type: drop}` (issue 31): objects dropped onto a support by MuJoCo at parse time.

Plausibility is checked independently of the engine on scenes/tabletop_scatter.yaml: every
dropped object rests on the table (its lowest vertex, trimesh on the placed render meshes, within
0.05 mm of the table's top), no two interpenetrate by more than 0.05 mm (FCL's GJK/EPA signed
distance between their convex hulls: an upper bound on the meshes' penetration), and the settled
state stays (released again at rest, nothing moves). The drop is bitwise deterministic across
processes, and the resolved spec (`to_yaml`, the dataset's cameras.json) reproduces it without
the engine.
"""
import json
import subprocess
import sys
from pathlib import Path

import fcl
import numpy as np
import pytest

from scenegen.assets.meshes import object_mesh, place
from scenegen.cli import main
from scenegen.errors import SpecError
from scenegen.physics import drop as drop_module
from scenegen.spec import load_spec, parse_spec, same_spec, spec_to_dict, to_yaml

ROOT = Path(__file__).resolve().parents[3]
SCATTER = ROOT / "scenes" / "tabletop_scatter.yaml"
TOL_M = 5e-5  # measured: lowest vertices 0.003-0.009 mm into the top, worst pair 0.002 mm


@pytest.fixture(scope="module")
def scatter():
    return load_spec(SCATTER)


def placed_meshes(spec):
    objects = {o.name: o for o in spec.objects}
    return {n: place(object_mesh(objects[n].geometry)[0], objects[n].transform)
            for n in (*spec.placement.objects, spec.placement.onto)}


def hull_object(mesh):
    h = mesh.convex_hull
    faces = np.hstack([np.full((len(h.faces), 1), 3), h.faces]).ravel()
    return fcl.CollisionObject(fcl.Convex(np.asarray(h.vertices, np.float64), len(h.faces), faces), fcl.Transform())


def test_every_object_rests_on_the_table(scatter):
    meshes = placed_meshes(scatter)
    table = meshes.pop("table")
    top = table.bounds[1][2]
    assert len(meshes) == 20
    for name, mesh in meshes.items():
        low = mesh.bounds[0][2]
        assert abs(low - top) < TOL_M, f"{name}: lowest vertex {1e3 * (low - top):.4f} mm from the top"
        assert (mesh.bounds[0][:2] > table.bounds[0][:2]).all() and (mesh.bounds[1][:2] < table.bounds[1][:2]).all()


def test_no_two_objects_interpenetrate(scatter):
    meshes = placed_meshes(scatter)
    meshes.pop("table")
    hulls = {n: hull_object(m) for n, m in meshes.items()}
    names = sorted(hulls)
    worst = min(fcl.distance(hulls[a], hulls[b], fcl.DistanceRequest(enable_signed_distance=True), fcl.DistanceResult())
                for i, a in enumerate(names) for b in names[i + 1:])
    assert worst > -TOL_M


def test_the_settled_state_stays(scatter):
    """Released again where they rest, at rest, for 0.5 s: no vertex moves by 0.05 mm."""
    objects = {o.name: o for o in scatter.objects}
    p = scatter.placement
    table = objects[p.onto]
    hull = drop_module.support_hull(object_mesh(table.geometry)[0].vertices * table.transform.scale,
                                     table.transform.world_from_object, "table")
    verts = [object_mesh(objects[n].geometry)[0].vertices * objects[n].transform.scale for n in p.objects]
    bodies = [drop_module.Body(n, v, p.poses[n]) for n, v in zip(p.objects, verts)]
    again = drop_module.settle(bodies, hull, drop_module.DropSettings(p.friction, 0.5, 1e-12))
    moved = max(np.abs(q.apply(v) - p.poses[n].apply(v)).max() for n, v, q in zip(p.objects, verts, again.poses))
    assert moved < TOL_M


def test_the_resolved_spec_reproduces_the_drop_without_the_engine(scatter, monkeypatch):
    def no_engine(*a, **k):
        raise AssertionError("the engine ran")

    monkeypatch.setattr(drop_module, "_simulate", no_engine)
    back = parse_spec(to_yaml(scatter), base_dir=scatter.base_dir)
    assert same_spec(back, scatter) and spec_to_dict(back) == spec_to_dict(scatter)
    assert all((back.placement.poses[n].matrix == scatter.placement.poses[n].matrix).all()
               for n in scatter.placement.objects)


SCRIPT = ("import json, sys; from scenegen.spec import load_spec; p = load_spec(sys.argv[1]).placement; "
          "print(json.dumps({n: [repr(float(x)) for x in p.poses[n].matrix.ravel()] for n in p.objects}))")


def in_parallel(*argvs) -> list[str]:
    """Run the commands at once (two fresh processes, no shared cache); their stdout."""
    procs = [subprocess.Popen(argv, stdout=subprocess.PIPE, text=True, cwd=ROOT) for argv in argvs]
    outs = [p.communicate(timeout=300)[0] for p in procs]
    assert [p.returncode for p in procs] == [0] * len(procs)
    return outs


def test_the_drop_is_bitwise_deterministic_across_processes(scatter):
    runs = in_parallel(*[[sys.executable, "-c", SCRIPT, str(SCATTER)]] * 2)
    assert runs[0] == runs[1]
    here = {n: [repr(float(x)) for x in scatter.placement.poses[n].matrix.ravel()] for n in scatter.placement.objects}
    assert json.loads(runs[0]) == here


DROP = """
objects:
  - {name: table, shape: {type: box, size: [0.6, 0.4, 0.04]}, transform: {translation: [0, 0, 0.5]}}
  - {name: ball, shape: {type: sphere, radius: 0.03}}
  - {name: cube, shape: {type: box, size: [0.05, 0.05, 0.05]}, transform: {rotation_deg: [0, 0, 20]}}
  - {name: sheet, shape: plane}
placement:
  type: drop
  onto: table
  objects: [ball, cube]
"""


def test_seed_and_orientation_are_used():
    base = parse_spec(DROP + "  seed: 1\n  orientation: yaw\n")
    other = parse_spec(DROP + "  seed: 2\n  orientation: yaw\n")
    assert not np.allclose(base.placement.poses["cube"].t, other.placement.poses["cube"].t)
    cube = base.placement.poses["cube"]
    assert abs(cube.R[2, 2] - 1.0) < 1e-6 and abs(cube.t[2] - (0.52 + 0.025)) < TOL_M  # upright on the top
    derived = parse_spec(DROP)
    assert derived.placement.seed == parse_spec(DROP).placement.seed  # derived from the scene seed


@pytest.mark.parametrize("tail,line,field,fragment", [
    ("  drop_height_m: -1\n", 11, "placement.drop_height_m", "expected a value >= 0 (metres), got -1"),
    ("  region: {min: [0.2, 0], max: [0.1, 0.1]}\n", 11, "placement.region.max", "expected max >= min"),
    ("  poses: {ball: {translation: [0, 0, 1]}}\n", 11, "placement.poses.cube", "missing required key 'cube'"),
])
def test_bad_values_are_named(tail, line, field, fragment):
    with pytest.raises(SpecError) as e:
        parse_spec(DROP + tail, file="drop.yaml")
    assert e.value.line == line and e.value.field == field and fragment in e.value.message


@pytest.mark.parametrize("old,new,fragment", [
    ("onto: table", "onto: tabel", "undefined object 'tabel' (did you mean 'table'?)"),
    ("[ball, cube]", "[ball, ghost]", "undefined object 'ghost'"),
    ("[ball, cube]", "[ball, ball]", "'ball' is named twice"),
    ("[ball, cube]", "[ball, table]", "'table' is the support"),
    ("[ball, cube]", "[ball, sheet]", "'sheet' is a plane: it has no volume"),
    ("[ball, cube]", "[]", "at least one object"),
    ("{name: ball, shape: {type: sphere, radius: 0.03}}",
     "{name: ball, shape: {type: sphere, radius: 0.03}, transform: {translation: [0, 0, 1]}}",
     "'ball' is dropped by `placement:`, which places it: its transform may give scale"),
    ("{name: ball, shape: {type: sphere, radius: 0.03}}",
     "{name: ball, shape: {type: sphere, radius: 0.03}, motion: {linear_velocity_mps: [1, 0, 0]}}",
     "'ball' moves"),
    ("{name: ball, shape: {type: sphere, radius: 0.03}}", "{name: ball, shape: {type: sphere, radius: 0.4}}",
     "'ball' (bounding radius 0.4 m) does not fit on the support 'table'"),
])
def test_bad_drops_are_named(old, new, fragment):
    text = DROP.replace(old, new)
    assert text != DROP
    with pytest.raises(SpecError) as e:
        parse_spec(text, file="drop.yaml")
    assert e.value.file == "drop.yaml" and e.value.line is not None and fragment in e.value.message, e.value.message


def test_an_object_that_falls_off_is_named():
    text = DROP.replace("objects: [ball, cube]", "objects: [ball]\n  region: {min: [0.5, 0], max: [0.5, 0]}\n"
                        "  settle_s: 0.5")
    with pytest.raises(SpecError, match="'ball' is still moving after settle_s 0.5 s .* it fell off the support "
                                        "'table'"):
        parse_spec(text, file="drop.yaml")


def test_a_variation_may_not_move_what_the_drop_placed():
    text = DROP + "variation: {objects: {cube: {yaw_deg: [0, 90]}}}\n"
    with pytest.raises(SpecError, match="'cube' takes part in the drop .* 'yaw_deg'"):
        parse_spec(text, file="drop.yaml")
    parse_spec(DROP + "variation: {objects: {sheet: {yaw_deg: [0, 90]}}}\n")  # not in the drop: fine


def test_validate_exits_2_with_one_line(tmp_path, capsys):
    bad = tmp_path / "bad.yaml"
    bad.write_text(DROP.replace("[ball, cube]", "[ball, sheet]"))
    assert main(["validate", str(bad)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"{bad}:10" in err[0] and "placement.objects[1]" in err[0]


@pytest.mark.render
def test_the_scene_renders_bitwise_deterministically(tmp_path):
    """scenes/tabletop_scatter.yaml at 64x48, twice in separate processes: the same manifest
    (every file's hash), and cameras.json records the settled poses."""
    spec = tmp_path / "tabletop_scatter.yaml"
    spec.write_text(SCATTER.read_text().replace("size: [320, 240]", "size: [64, 48]"))
    outs = [tmp_path / "a", tmp_path / "b"]
    in_parallel(*[[sys.executable, "-c", "import sys; from scenegen.cli import main; sys.exit(main(sys.argv[1:]))",
                   "render", str(spec), "-o", str(out), "--spp", "4", "-q"] for out in outs])
    a, b = ((o / "manifest.json").read_bytes() for o in outs)
    assert a == b and json.loads(a)["files"]
    recorded = json.loads((outs[0] / "cameras.json").read_text())["spec"]["placement"]["poses"]
    settled = load_spec(spec).placement.poses
    assert recorded.keys() == settled.keys()
    assert all(np.array_equal(recorded[n]["R"], settled[n].R) and np.array_equal(recorded[n]["t"], settled[n].t)
               for n in settled)
