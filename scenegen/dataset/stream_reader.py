"""Typed access to a dataset's streams (:mod:`.streams`): ``Dataset(path).streams``.

    >>> d = Dataset("out/vio")                      # doctest: +SKIP
    >>> d.streams.names                              # complete streams, sorted
    >>> imu = d.streams["imu0"]                      # Stream: kind, sensor, schema
    >>> t, acc = imu.time_s, imu.field("accel_mps2")  # all samples, chunks concatenated
    >>> for chunk in imu.chunks(): ...               # {time_s, field: ...} one chunk at a time
"""
from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from scenegen.dataset.codecs.json import read_json
from scenegen.dataset.errors import DatasetError
from scenegen.dataset.layout import STREAMS, check_name, stream_doc_path
from scenegen.dataset.streams import TIME_KEY, StreamSchema, check_stream_document, decode_chunk


class Stream:
    """One complete stream: ``kind``, ``sensor``, ``schema`` (:class:`StreamSchema`), ``samples``;
    its arrays through :meth:`chunks`, :meth:`field` and :attr:`time_s`."""

    def __init__(self, dataset, name: str):
        self._ds, self.name = dataset, name
        doc = dataset.read(stream_doc_path(name), read_json, f"stream {name!r}")
        try:
            self.schema: StreamSchema = check_stream_document(doc, name)
        except ValueError as e:
            raise DatasetError(f"{dataset.path(stream_doc_path(name))}: {e}") from None
        self._chunks = doc["chunks"]
        self.samples: int = doc["samples"]

    @property
    def kind(self) -> str:
        return self.schema.kind

    @property
    def sensor(self) -> str:
        return self.schema.sensor

    def __repr__(self) -> str:
        return f"Stream({self.name!r}: {self.kind} of sensor {self.sensor!r}, {self.samples} samples)"

    def chunks(self) -> Iterator[dict[str, np.ndarray]]:
        """Each chunk's arrays in order: ``time_s`` (n,) seconds and every field (n, *shape)."""
        for entry in self._chunks:
            yield self._ds.read(entry["path"], lambda p, e=entry: decode_chunk(self.schema, p.read_bytes(), e),
                                f"chunk of stream {self.name!r}")

    def field(self, name: str) -> np.ndarray:
        """(samples, *shape) one field over the whole stream (``time_s`` for the times)."""
        if name != TIME_KEY and name not in {f.name for f in self.schema.fields}:
            raise KeyError(f"stream {self.name!r} has no field {name!r}; it has "
                           f"{[TIME_KEY] + [f.name for f in self.schema.fields]}")
        return np.concatenate([c[name] for c in self.chunks()])

    @property
    def time_s(self) -> np.ndarray:
        """(samples,) float64 sample times, seconds on the sequence clock."""
        return self.field(TIME_KEY)


class Streams:
    """The complete streams of a dataset, by name."""

    def __init__(self, dataset):
        self._ds = dataset
        names = []
        for rel in dataset.manifest["files"]:
            parts = rel.split("/")
            if len(parts) == 3 and parts[0] == STREAMS and parts[2] == "stream.json":
                try:
                    names.append(check_name("stream", parts[1]))
                except ValueError as e:
                    raise DatasetError(f"{dataset.root / 'manifest.json'}: {e}") from None
        self.names: tuple[str, ...] = tuple(sorted(names))

    def __contains__(self, name: str) -> bool:
        return name in self.names

    def __iter__(self):
        return iter(self.names)

    def __len__(self) -> int:
        return len(self.names)

    def __getitem__(self, name: str) -> Stream:
        if name not in self.names:
            raise KeyError(f"no complete stream {name!r} in {self._ds.root}; streams: {list(self.names)}")
        return Stream(self._ds, name)

    def of_kind(self, kind: str) -> tuple[str, ...]:
        """Names of the streams of one sensor kind."""
        return tuple(n for n in self.names if self[n].kind == kind)
