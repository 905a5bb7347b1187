"""A run's logs cut back to its checkpoint on resume (host only).

A run killed between two checkpoints has logged iterations that the resumed run
trains again. So that a resumed run's logs equal an uninterrupted run's, resume
first drops from `metrics.jsonl` every record after the checkpoint's iteration and
from the TensorBoard event files every summary after its env steps. A line or
record torn by the kill (the last one written) is dropped with a warning.
"""

from __future__ import annotations

import json
import struct
import warnings
from pathlib import Path

from leas_jax.files import atomic_write_bytes, atomic_write_text


class LogWarning(UserWarning):
    """A torn or unreadable log record was dropped."""


def truncate_metrics(path: Path, iteration: int) -> list[dict]:
    """Keep the records of `metrics.jsonl` with `iteration` <= the given one; rewrite the file.

    Args:
        path: the metrics.jsonl file (absent: nothing to do).
        iteration: the resumed state's iteration count (0: drop everything).

    Returns:
        the records kept, in file order.
    """
    path = Path(path)
    if not path.exists():
        return []
    kept, dropped = [], []
    for number, line in enumerate(path.read_text(errors="replace").splitlines(), start=1):
        if not line.strip():
            continue
        try:
            record = json.loads(line)
            step = int(record["iteration"])
        except (ValueError, KeyError, TypeError):
            dropped.append(number)
            continue
        if step <= iteration:
            kept.append(record)
    if dropped:
        warnings.warn(
            f"{path}: dropped unreadable line(s) {', '.join(map(str, dropped))} (torn by an interrupted run)",
            LogWarning,
            stacklevel=2,
        )
    atomic_write_text(path, "".join(json.dumps(r) + "\n" for r in kept))
    return kept


def _records(data: bytes):
    """(start, end) byte spans of the whole TFRecord records of an event file; stops at a torn one."""
    from tensorboardX.record_writer import masked_crc32c

    offset = 0
    while offset + 12 <= len(data):
        header = data[offset : offset + 8]
        (length,) = struct.unpack("<Q", header)
        (length_crc,) = struct.unpack("<I", data[offset + 8 : offset + 12])
        end = offset + 12 + length + 4
        if length_crc != masked_crc32c(header) or end > len(data):
            return
        payload = data[offset + 12 : offset + 12 + length]
        (payload_crc,) = struct.unpack("<I", data[end - 4 : end])
        if payload_crc != masked_crc32c(payload):
            return
        yield offset, end, payload
        offset = end


def truncate_events(folder: Path, env_steps: int) -> None:
    """Drop the TensorBoard summaries with step > `env_steps` from every event file of `folder`.

    Non-summary events (the file-version header) are kept; a torn last record is
    dropped (with a warning). Files are rewritten atomically, only when they change.
    """
    from tensorboardX.proto.event_pb2 import Event

    folder = Path(folder)
    if not folder.is_dir():
        return
    for file in sorted(folder.glob("events.out.tfevents.*")):
        data = file.read_bytes()
        kept, covered = [], 0
        for start, end, payload in _records(data):
            covered = end
            event = Event()
            event.ParseFromString(payload)
            if not event.HasField("summary") or event.step <= env_steps:
                kept.append(data[start:end])
        if covered < len(data):
            warnings.warn(f"{file}: dropped a torn record at byte {covered}", LogWarning, stacklevel=2)
        new = b"".join(kept)
        if new != data:
            atomic_write_bytes(file, new)
