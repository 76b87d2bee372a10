"""A long run's journal: what it has finished, kept beside its output as it goes, so that the run, interrupted and
rerun with --resume, does only what is missing and ends exactly as an uninterrupted run would.

The journal is a file of pickles (exact: floats, integer keys and numpy arrays come back as they went in). The first
is the run's definition, everything that changes its results (trackers, scenarios, seeds, overrides, ...); each
further one a (key, value) of a finished piece of work, written and flushed as the piece finishes. A piece cut off by
the interruption is simply not there. Resuming with another definition is refused, saying what differs. The journal
is removed once the run has finished and written its outputs.
"""

from __future__ import annotations

import pickle
from pathlib import Path
from typing import Any, Hashable, Mapping

MISSING = object()


class JournalMismatch(ValueError):
    """The journal beside an output was written by a run defined otherwise."""


def path_beside(out: str | Path) -> Path:
    """Where the journal of a run writing `out` (a file or a folder) is kept: `<out>.journal`."""
    return Path(f"{out}.journal")


class Journal:
    """The finished pieces of a run defined by `definition` (a mapping of plain values), at `path`. With
    `resume=True` an existing journal's pieces are read back (its definition must equal this one); without, any
    journal there is replaced."""

    def __init__(self, path: str | Path, definition: Mapping[str, Any], resume: bool):
        self.path, self.definition = Path(path), dict(definition)
        self.pieces: dict[Hashable, Any] = {}
        if resume and self.path.exists():
            self._read()
            self.file = self.path.open("ab")
        else:
            self.file = self.path.open("wb")
            self._write(self.definition)
        self.resumed = len(self.pieces)

    def _read(self) -> None:
        with self.path.open("rb") as f:
            try:
                stored = pickle.load(f)
            except (EOFError, pickle.UnpicklingError) as err:
                raise JournalMismatch(f"journal {self.path}: unreadable ({err}); remove it or add --force to start "
                                      "over") from None
            if stored != self.definition:
                differ = [f"{k}: {stored.get(k)!r} then, {self.definition.get(k)!r} now"
                          for k in sorted(set(stored) | set(self.definition), key=str)
                          if stored.get(k) != self.definition.get(k)]
                raise JournalMismatch(f"journal {self.path} is of another run ({'; '.join(differ)}): rerun it as it "
                                      "was, or add --force to start over")
            while True:
                start = f.tell()
                try:
                    key, value = pickle.load(f)
                except (EOFError, pickle.UnpicklingError, ValueError, TypeError):  # the end, or a piece cut off
                    break
                self.pieces[key] = value
            end = start
        with self.path.open("r+b") as f:
            f.truncate(end)  # drop a piece cut off mid-write, so new pieces follow whole ones

    def _write(self, item) -> None:
        pickle.dump(item, self.file, protocol=pickle.HIGHEST_PROTOCOL)
        self.file.flush()

    def get(self, key: Hashable, default=MISSING):
        """The value of finished piece `key`, or `default` if it has not finished."""
        return self.pieces.get(key, default)

    def __contains__(self, key: Hashable) -> bool:
        return key in self.pieces

    def put(self, key: Hashable, value: Any) -> None:
        """Record piece `key` as finished with `value`."""
        self.pieces[key] = value
        self._write((key, value))

    def close(self) -> None:
        self.file.close()

    def finish(self) -> None:
        """The run is done and its outputs written: the journal is no longer needed."""
        self.close()
        self.path.unlink(missing_ok=True)
