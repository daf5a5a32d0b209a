"""Streams beside views: the timestamped samples of a sensor that are not one image per view (an
IMU's samples, a LiDAR's beams, wheel odometry, a depth camera's raw frames), stored in chunks.

On disk (:mod:`.layout`; docs/dataset_format.md, "Streams")::

    streams/<name>/chunk_<k>.npz   chunk k (0, 1, ...): ``time_s`` (n,) float64 and one array per
                                   field, (n, *shape) of the field's dtype
    streams/<name>/stream.json     {"kind", "sensor", "schema", "chunks": [{"path", "samples",
                                   "first_time_s", "last_time_s"}], "samples", "format_version"}

Times are seconds on the sequence clock (docs/conventions.md), strictly increasing over the whole
stream. Every file is written atomically and hashed in the manifest like a view's; a chunk is
recorded as it is written (a killed run's ``--resume`` keeps it), and ``stream.json`` is written
last: a stream is complete when its document is listed. :func:`check_stream_document` is the one
check of a document, for the writer, the reader and ``verify``.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

import numpy as np

from scenegen.dataset.codecs.npy import decode_npz, encode_npz
from scenegen.dataset.layout import check_name, stream_chunk_path

STREAM_FORMAT_VERSION = 1
TIME_KEY = "time_s"
#: dtypes a field may have (little-endian on disk, as NPY writes them here).
FIELD_DTYPES = ("float32", "float64", "int8", "int16", "int32", "int64", "uint8", "uint16", "uint32", "bool")
#: Samples per chunk a writer should aim at: files of a few MB, each one journal line.
DEFAULT_CHUNK_SAMPLES = 65536


@dataclass(frozen=True)
class StreamField:
    """One field of a stream's samples: ``dtype`` (a :data:`FIELD_DTYPES` name), per-sample
    ``shape`` (() for a scalar), ``unit`` (e.g. 'm/s^2') and what it is, in ``doc``."""

    name: str
    dtype: str
    shape: tuple[int, ...] = ()
    unit: str = ""
    doc: str = ""

    def __post_init__(self):
        check_name("stream field", self.name)
        if self.name == TIME_KEY:
            raise ValueError(f"stream field {TIME_KEY!r} is reserved for the sample times")
        if self.dtype not in FIELD_DTYPES:
            raise ValueError(f"stream field {self.name!r}: dtype must be one of {FIELD_DTYPES}, got {self.dtype!r}")
        shape = tuple(self.shape)
        if not all(isinstance(n, (int, np.integer)) and not isinstance(n, bool) and n > 0 for n in shape):
            raise ValueError(f"stream field {self.name!r}: shape must be positive ints, got {self.shape!r}")
        object.__setattr__(self, "shape", tuple(int(n) for n in shape))

    def to_dict(self) -> dict:
        return {"dtype": self.dtype, "shape": list(self.shape), "unit": self.unit, "doc": self.doc}


@dataclass(frozen=True)
class StreamSchema:
    """What a stream holds: its ``kind`` (the sensor kind, e.g. 'imu'), the ``sensor`` that made it
    (its name in the spec) and its ``fields``, in order."""

    kind: str
    sensor: str
    fields: tuple[StreamField, ...]

    def __post_init__(self):
        check_name("stream kind", self.kind)
        check_name("sensor", self.sensor)
        names = [f.name for f in self.fields]
        if not names or len(set(names)) != len(names):
            raise ValueError(f"a stream needs at least one field and distinct field names, got {names}")

    def to_dict(self) -> dict:
        return {f.name: f.to_dict() for f in self.fields}

    @classmethod
    def from_document(cls, doc: Mapping) -> "StreamSchema":
        fields = tuple(StreamField(name, d["dtype"], tuple(d["shape"]), d.get("unit", ""), d.get("doc", ""))
                       for name, d in doc["schema"].items())
        return cls(doc["kind"], doc["sensor"], fields)


def encode_chunk(schema: StreamSchema, time_s, fields: Mapping[str, np.ndarray]) -> tuple[bytes, dict]:
    """(NPZ bytes, the chunk's entry of stream.json without its path) of samples at ``time_s``
    (n,) seconds, strictly increasing, with one array (n, *shape) per schema field, cast to the
    field's dtype (a float that does not fit the dtype is refused)."""
    t = np.asarray(time_s, np.float64)
    if t.ndim != 1 or not len(t) or not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise ValueError("stream chunk: time_s must be a non-empty 1-D array of finite, strictly increasing seconds")
    missing = [f.name for f in schema.fields if f.name not in fields]
    extra = sorted(set(fields) - {f.name for f in schema.fields})
    if missing or extra:
        raise ValueError(f"stream chunk: fields missing {missing}, not in the schema {extra}")
    arrays = {TIME_KEY: t}
    for f in schema.fields:
        a = np.asarray(fields[f.name])
        if a.shape != (len(t), *f.shape):
            raise ValueError(f"stream chunk: field {f.name!r} must have shape {(len(t), *f.shape)}, got {a.shape}")
        cast = a.astype(f.dtype)
        if np.issubdtype(np.dtype(f.dtype), np.integer) and not np.array_equal(cast, a):
            raise ValueError(f"stream chunk: field {f.name!r} has values that are not {f.dtype}")
        arrays[f.name] = np.ascontiguousarray(cast.astype(np.dtype(f.dtype).newbyteorder("<")))
    entry = {"samples": int(len(t)), "first_time_s": float(t[0]), "last_time_s": float(t[-1])}
    return encode_npz(arrays), entry


def decode_chunk(schema: StreamSchema, data: bytes, entry: Mapping) -> dict[str, np.ndarray]:
    """{``time_s``: (n,), field: (n, *shape)} of a chunk's bytes, checked against the schema and
    the chunk's entry in stream.json (ValueError saying what differs)."""
    arrays = decode_npz(data)
    want = {TIME_KEY: ("float64", ())} | {f.name: (f.dtype, f.shape) for f in schema.fields}
    if set(arrays) != set(want):
        raise ValueError(f"chunk holds {sorted(arrays)}, the schema says {sorted(want)}")
    n = int(entry["samples"])
    for name, (dtype, shape) in want.items():
        a = arrays[name]
        if a.dtype != np.dtype(dtype) or a.shape != (n, *shape):
            raise ValueError(f"chunk field {name!r} is {a.dtype} {a.shape}, expected {dtype} {(n, *shape)}")
    t = arrays[TIME_KEY]
    if (n and (t[0] != entry["first_time_s"] or t[-1] != entry["last_time_s"])) or np.any(np.diff(t) <= 0):
        raise ValueError("chunk times differ from stream.json or do not increase")
    return arrays


def stream_document(name: str, schema: StreamSchema, entries: list[dict]) -> dict:
    """The stream.json document of a complete stream (entries as :func:`encode_chunk` returns
    them, in chunk order); checked with :func:`check_stream_document`."""
    chunks = [{"path": stream_chunk_path(name, k), **e} for k, e in enumerate(entries)]
    doc = {"format_version": STREAM_FORMAT_VERSION, "name": name, "kind": schema.kind, "sensor": schema.sensor,
           "schema": schema.to_dict(), "chunks": chunks, "samples": sum(e["samples"] for e in entries)}
    check_stream_document(doc, name)
    return doc


def check_stream_document(doc, name: str) -> StreamSchema:
    """The schema of a stream.json document read from a file, after checking everything a reader
    relies on: names (they become paths), chunk paths, counts and time order. ValueError saying
    what is wrong."""
    if not isinstance(doc, dict):
        raise ValueError(f"stream {name!r}: stream.json must be an object")
    need = {"format_version", "name", "kind", "sensor", "schema", "chunks", "samples"}
    if set(doc) != need:
        raise ValueError(f"stream {name!r}: stream.json must have the keys {sorted(need)}, has {sorted(doc)}")
    if doc["format_version"] != STREAM_FORMAT_VERSION or doc["name"] != name:
        raise ValueError(f"stream {name!r}: format_version {doc['format_version']!r} (this reader knows "
                         f"{STREAM_FORMAT_VERSION}) or name {doc['name']!r} does not match its folder")
    try:
        schema = StreamSchema.from_document(doc)
    except (KeyError, TypeError, AttributeError) as e:
        raise ValueError(f"stream {name!r}: malformed schema ({e!r})") from None
    chunks = doc["chunks"]
    if not isinstance(chunks, list) or not chunks:
        raise ValueError(f"stream {name!r}: no chunks")
    last, total = -np.inf, 0
    for k, c in enumerate(chunks):
        if not isinstance(c, dict) or c.get("path") != stream_chunk_path(name, k):
            raise ValueError(f"stream {name!r}: chunk {k} must be at {stream_chunk_path(name, k)}")
        n, t0, t1 = c.get("samples"), c.get("first_time_s"), c.get("last_time_s")
        if (isinstance(n, bool) or not isinstance(n, int) or n < 1 or not all(isinstance(x, float) for x in (t0, t1))
                or not (last < t0 <= t1) or not np.isfinite(t1)):
            raise ValueError(f"stream {name!r}: chunk {k} needs samples >= 1 and finite times after the previous chunk's")
        last, total = t1, total + n
    if doc["samples"] != total:
        raise ValueError(f"stream {name!r}: samples is {doc['samples']!r}, the chunks hold {total}")
    return schema
