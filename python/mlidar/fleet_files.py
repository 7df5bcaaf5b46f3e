"""Files of a fleet run written whole: a temporary name, flushed to disk, renamed into place."""

from __future__ import annotations

import os
from datetime import datetime, timezone
from pathlib import Path


def write_text_atomically(path: Path, text: str) -> None:
    stage = path.with_name(f".{path.name}.tmp-{os.getpid()}")
    with open(stage, "w") as handle:
        handle.write(text)
        handle.flush()
        os.fsync(handle.fileno())
    os.rename(stage, path)


def utc_now() -> str:
    return datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
