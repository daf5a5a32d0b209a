"""Writing a stream beside the views (:mod:`.streams`) through a :class:`DatasetWriter`.

    sw = StreamWriter(writer, "imu0", schema)       # schema: kind, sensor, fields
    for k, (time_s, fields) in enumerate(chunks):   # deterministic chunks, in time order
        sw.write_chunk(k, time_s, fields)           # atomic, hashed, one journal line
    sw.close()                                      # stream.json: the stream is complete

A resumed run calls the same sequence: a chunk already recorded with the same bytes is not
written again, one with other bytes is refused (outputs must be deterministic), so a killed run
resumes to the bytes of one run.
"""
from __future__ import annotations

from typing import Mapping

import numpy as np

from scenegen.dataset.codecs.json import encode_json
from scenegen.dataset.files import sha256_bytes
from scenegen.dataset.layout import check_name, stream_chunk_path, stream_doc_path
from scenegen.dataset.streams import StreamSchema, encode_chunk, stream_document


class StreamWriter:
    """Chunks of one stream, written in order through ``writer`` (a DatasetWriter)."""

    def __init__(self, writer, name: str, schema: StreamSchema):
        self._w, self.name, self.schema = writer, check_name("stream", name), schema
        self._entries: list[dict] = []

    def write_chunk(self, index: int, time_s, fields: Mapping[str, np.ndarray]) -> None:
        """Chunk ``index`` (the next one: 0, 1, ...) of samples at ``time_s`` (n,) seconds, after
        the previous chunk's, with one (n, *shape) array per schema field."""
        if index != len(self._entries):
            raise ValueError(f"stream {self.name!r}: chunk {index} written after {len(self._entries)} chunks")
        data, entry = encode_chunk(self.schema, time_s, fields)
        if self._entries and entry["first_time_s"] <= self._entries[-1]["last_time_s"]:
            raise ValueError(f"stream {self.name!r}: chunk {index} starts at {entry['first_time_s']} s, not after "
                             f"the previous chunk's last sample ({self._entries[-1]['last_time_s']} s)")
        rel = stream_chunk_path(self.name, index)
        if self._w.file_sha256(rel) != sha256_bytes(data):  # a resumed run: the same chunk is on disk
            self._w.write_file(rel, data)
        self._entries.append(entry)

    def close(self) -> dict:
        """Write stream.json (the stream is complete); returns the document."""
        doc = stream_document(self.name, self.schema, self._entries)
        self._w.write_file(stream_doc_path(self.name), encode_json(doc))
        return doc
