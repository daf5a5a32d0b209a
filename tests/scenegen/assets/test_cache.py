"""The procedural asset cache (scenegen/assets/cache.py): hits are bitwise the fresh assets."""
import numpy as np
import pytest

from scenegen.assets import blob, cache, meshes, textures
from scenegen.spec import parse_spec

SPEC = """
objects:
  - name: rock
    shape: {type: blob, radius: 0.3, amplitude: 0.2, frequency: 2.0, subdivisions: 3}
    material: {type: diffuse, texture: {type: natural, params: {size_px: 64}}}
cameras:
  cam: {model: pinhole, size: [16, 12], fx: 14, fy: 14, cx: 7.5, cy: 5.5}
views:
  - camera: cam
    look_at: [{eye: [1, 1, 1], target: [0, 0, 0]}]
"""


@pytest.fixture
def disk(tmp_path, monkeypatch):
    monkeypatch.setenv(cache.CACHE_ENV, str(tmp_path / "cache"))
    monkeypatch.setattr(cache, "_MEMORY", type(cache._MEMORY)())
    return tmp_path / "cache"


def _rock():
    return parse_spec(SPEC, file="t.yaml").objects[0]


def test_texture_and_blob_hits_are_bitwise_fresh(disk, monkeypatch):
    obj = _rock()
    tex = obj.material.texture
    fresh_tex = textures.make_texture(tex.kind, dict(tex.params), tex.seed)
    g = obj.geometry
    fresh = blob.blob(g.radius, g.amplitude, g.frequency, g.seed, g.subdivisions)
    for _ in range(2):  # made (and stored), then from memory
        img = meshes.texture_image(tex)
        assert img.dtype == fresh_tex.dtype and img.tobytes() == fresh_tex.tobytes() and not img.flags.writeable
        m, _ = meshes.object_mesh(g)
        for a, b in ((m.vertices, fresh.vertices), (m.faces, fresh.faces), (m.visual.uv, fresh.visual.uv)):
            assert np.asarray(a).dtype == np.asarray(b).dtype and np.array_equal(a, b)
    assert len(list(disk.glob("texture-*.npz"))) == 1 and len(list(disk.glob("blob-*.npz"))) == 1
    monkeypatch.setattr(cache, "_MEMORY", type(cache._MEMORY)())  # a new process: from disk
    monkeypatch.setattr(textures, "make_texture", lambda *a: pytest.fail("made again"))
    assert meshes.texture_image(tex).tobytes() == fresh_tex.tobytes()


def test_damaged_cache_file_is_made_again(disk, monkeypatch):
    tex = _rock().material.texture
    ref = meshes.texture_image(tex).copy()
    (path,) = disk.glob("texture-*.npz")
    data = bytearray(path.read_bytes())
    data[len(data) // 2] ^= 0xFF
    path.write_bytes(bytes(data))
    monkeypatch.setattr(cache, "_MEMORY", type(cache._MEMORY)())
    assert np.array_equal(meshes.texture_image(tex), ref)


def test_key_depends_on_code_and_params(disk, monkeypatch):
    a = cache.asset_key("texture", {"size": 1})
    assert a != cache.asset_key("texture", {"size": 2}) and a != cache.asset_key("blob", {"size": 1})
    monkeypatch.setattr(cache, "code_fingerprint", lambda: "another version of the code")
    assert cache.asset_key("texture", {"size": 1}) != a


def test_off_disables_the_disk(tmp_path, monkeypatch):
    monkeypatch.setenv(cache.CACHE_ENV, "off")
    assert cache.cache_dir() is None
    monkeypatch.setattr(cache, "_MEMORY", type(cache._MEMORY)())
    meshes.texture_image(_rock().material.texture)
    assert not list(tmp_path.rglob("*.npz"))
