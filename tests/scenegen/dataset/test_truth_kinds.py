"""TruthKind names the per-pixel truth kinds once: its members are the stored keys (equal strings,
same hashes), its table the stored channels, and truth keyed by plain strings or by kinds encodes
to the same bytes."""
import numpy as np

from scenegen.dataset import TruthKind
from scenegen.dataset.codecs import decode_exr
from scenegen.dataset.truth import (TRUTH_FLOAT_CHANNELS, TRUTH_ID_KEYS, TRUTH_KEYS, TRUTH_KIND_INFO, decode_truth,
                                    encode_truth)

# The format as docs/dataset_format.md states it (written out here, not derived from the enum).
STORED = {
    "depth_z": ("truth", "depth_z", None, np.float32, np.inf),
    "range": ("truth", "range", None, np.float32, np.inf),
    "points_world": ("truth", "P_world", ("X", "Y", "Z"), np.float32, np.nan),
    "points_cam": ("truth", "P_cam", ("X", "Y", "Z"), np.float32, np.nan),
    "normals_world": ("truth", "N_world", ("X", "Y", "Z"), np.float32, np.nan),
    "normals_cam": ("truth", "N_cam", ("X", "Y", "Z"), np.float32, np.nan),
    "uv": ("truth", "uv", ("U", "V"), np.float32, np.nan),
    "object_id": ("ids", "object_id", None, np.uint32, 0),
    "instance_id": ("ids", "instance_id", None, np.uint32, 0),
    "valid": ("valid", None, None, np.bool_, False),
}


def test_kinds_are_the_stored_keys():
    assert [k.value for k in TruthKind] == list(STORED) == list(TRUTH_KEYS)
    for k in TruthKind:
        assert k == k.value and hash(k) == hash(k.value) and f"{k}" == str(k) == k.value
        assert {k.value: 1}[k] == 1 and {k: 1}[k.value] == 1


def test_kind_info_is_the_documented_storage():
    for k, (file, prefix, comps, dtype, miss) in STORED.items():
        info = TruthKind(k).info
        assert info is TRUTH_KIND_INFO[k]
        assert (info.file, info.exr_prefix, info.components, info.dtype) == (file, prefix, comps, dtype)
        assert info.miss == miss or (np.isnan(miss) and np.isnan(info.miss))
        assert info.unit
    assert dict(TRUTH_FLOAT_CHANNELS) == {k: v[1:3] for k, v in STORED.items() if v[0] == "truth"}
    assert list(TRUTH_ID_KEYS) == ["object_id", "instance_id"]


def truth_by_string(H=5, W=7, seed=3) -> dict:
    """A truth dict keyed by plain strings that obeys the miss convention (random hits)."""
    rng = np.random.default_rng(seed)
    valid = rng.random((H, W)) < 0.7
    out = {"valid": valid}
    for k, (file, _, comps, dtype, miss) in STORED.items():
        if file == "truth":
            a = rng.uniform(0.1, 5, (H, W) + ((len(comps),) if comps else ())).astype(np.float32)
        elif file == "ids":
            a = rng.integers(1, 2**32, (H, W), dtype=np.uint32)
        else:
            continue
        a[~valid] = miss
        out[k] = a
    return out


def test_string_and_kind_keys_encode_to_the_same_bytes():
    by_string = truth_by_string()
    by_kind = {TruthKind(k): v for k, v in by_string.items()}
    files_s, files_k = encode_truth(by_string), encode_truth(by_kind)
    assert files_s == files_k
    ids = decode_exr(files_k["ids"])
    assert list(ids) == ["instance_id", "object_id"] and all(type(n) is str for n in ids)  # EXR order
    floats = decode_exr(files_k["truth"])
    assert all(type(n) is str for n in floats)
    back = decode_truth(floats, ids, np.where(by_string["valid"], 255, 0).astype(np.uint8))
    for k in STORED:  # a decoded truth dict answers both spellings
        np.testing.assert_array_equal(back[k], by_string[k])
        np.testing.assert_array_equal(back[TruthKind(k)], by_string[k])
