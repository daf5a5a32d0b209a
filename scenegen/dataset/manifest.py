"""``manifest.json``: a dataset's identity, its views' status and every file's SHA-256.

The manifest checks itself: ``manifest_sha256`` is the SHA-256 of the canonical JSON of the rest,
so a changed byte anywhere in it is detected. It holds no timestamps or machine paths: the same
spec, seed, variant and software give byte-identical manifests.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any, Mapping

from scenegen.dataset.codecs.json import decode_json, encode_json
from scenegen.dataset.errors import DatasetError
from scenegen.dataset.files import sha256_bytes
from scenegen.dataset.layout import MANIFEST

FORMAT = "scenegen-dataset"
FORMAT_VERSION = 1
STATUS_COMPLETE = "complete"
STATUS_PENDING = "pending"

IDENTITY_KEYS = ("format", "format_version", "spec_sha256", "seed", "variant", "versions")
MANIFEST_KEYS = IDENTITY_KEYS + ("views", "files", "manifest_sha256")


def manifest_bytes(body: Mapping[str, Any]) -> bytes:
    """Canonical manifest bytes: ``body`` plus ``manifest_sha256``, the SHA-256 of the canonical
    JSON of ``body`` itself (so a changed byte anywhere in manifest.json is detected)."""
    return manifest_bytes_and_sha256(body)[0]


def manifest_bytes_and_sha256(body: Mapping[str, Any]) -> tuple[bytes, str]:
    """:func:`manifest_bytes` and the ``manifest_sha256`` they hold.

    The body is encoded once (JSON encoding is most of the cost of a large manifest): with sorted
    keys and an indent of 2, the manifest is the body's text with the line
    ``  "manifest_sha256": ...,`` inserted before the top-level ``"seed"`` line."""
    body = {k: v for k, v in body.items() if k != "manifest_sha256"}
    text = encode_json(body)
    sha = sha256_bytes(text)
    anchor = b'\n  "seed": '
    if "seed" in body and text.count(anchor) == 1 and not any("manifest_sha256" < k < "seed" for k in body):
        return text.replace(anchor, b'\n  "manifest_sha256": "' + sha.encode() + b'",' + anchor, 1), sha
    return encode_json({**body, "manifest_sha256": sha}), sha  # any other body: encode again


def manifest_integrity_error(data: bytes) -> tuple[dict | None, str | None]:
    """Parse manifest bytes; return (manifest, None) or (None or manifest, reason it is corrupt)."""
    try:
        m = decode_json(data)
    except (UnicodeDecodeError, ValueError) as e:
        return None, f"not valid JSON ({e})"
    if not isinstance(m, dict) or set(m) != set(MANIFEST_KEYS):
        keys = sorted(m) if isinstance(m, dict) else type(m).__name__
        return None, f"expected keys {sorted(MANIFEST_KEYS)}, got {keys}"
    if manifest_bytes(m) != data:
        return m, "content does not match its manifest_sha256 (or is not in canonical form)"
    return m, None


def load_manifest(root: Path) -> dict:
    """Read and check manifest.json; raise DatasetError if absent, corrupt or of another format."""
    path = root / MANIFEST
    if not path.is_file():
        raise DatasetError(f"{root}: no {MANIFEST}; not a scenegen dataset")
    m, err = manifest_integrity_error(path.read_bytes())
    if err:
        raise DatasetError(f"{path}: corrupted: {err}")
    if m["format"] != FORMAT:
        raise DatasetError(f"{path}: format is {m['format']!r}, expected {FORMAT!r}")
    if m["format_version"] != FORMAT_VERSION:
        raise DatasetError(f"{path}: format_version {m['format_version']!r} is not supported"
                           f" (this reader knows {FORMAT_VERSION})")
    return m
