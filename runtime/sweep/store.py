"""The output folder of a sweep: written chunk by chunk, so that an interrupted sweep resumes.

    OUT/sweep.json                   what the sweep is (the resume check) and its task size
    OUT/chunks/part-A-B.parquet      the rows of samples A..B-1, each file written atomically
    OUT/results.parquet              all rows, in sample order, once every chunk is there

A chunk file exists only complete (written to a temporary name, then renamed), so after a
kill the folder holds whole chunks and nothing else that counts: a restart computes the
missing ones only.  The rows of a sample depend on the sweep file and the sample index only,
so the resumed results equal an uninterrupted run's byte for byte.
"""
import json
import pathlib

import pyarrow as pa
import pyarrow.parquet as pq

from ..scenarios.atomic import atomic_path, write_text

MANIFEST = "sweep.json"
RESULTS = "results.parquet"
CHUNKS = "chunks"


class SweepStore:
    """The folder `folder` of the sweep `spec`, split into tasks of `samples_per_task` samples."""

    def __init__(self, folder, spec, samples_per_task):
        self.folder = pathlib.Path(folder)
        self.spec = spec
        self.samples_per_task = samples_per_task

    @classmethod
    def open(cls, folder, spec, choose_samples_per_task):
        """Create the folder for `spec`, or reopen it to resume; refuses a folder of another sweep.

        `choose_samples_per_task()` is called only for a new folder (a resumed sweep keeps its
        tasks, although its rows would be the same with any split).
        """
        folder = pathlib.Path(folder)
        if folder.exists() and not folder.is_dir():
            raise ValueError(f"--out: {folder} exists and is not a folder")
        identity = json.loads(json.dumps(spec.identity()))
        manifest = folder / MANIFEST
        if manifest.is_file():
            try:
                data = json.loads(manifest.read_text(encoding="utf-8"))
                same, per_task = data["identity"] == identity, int(data["samples_per_task"])
            except (ValueError, KeyError, TypeError) as exc:
                raise ValueError(f"--out: {manifest} is not a sweep manifest ({exc}); choose another folder") from None
            if not same:
                raise ValueError(f"--out: {folder} holds the results of a different sweep (another sweep "
                                 f"file, seed or sample count); choose another folder")
            return cls(folder, spec, per_task)
        if folder.is_dir() and any(folder.iterdir()):
            raise ValueError(f"--out: {folder} is not empty and holds no sweep; choose another folder")
        (folder / CHUNKS).mkdir(parents=True, exist_ok=True)
        per_task = int(choose_samples_per_task())
        write_text(manifest, json.dumps({"sweep": spec.name, "source": spec.source, "samples_per_task": per_task,
                                         "identity": identity}, indent=1) + "\n")
        return cls(folder, spec, per_task)

    def chunks(self):
        """(start, stop) of every task, in sample order."""
        n, k = self.spec.samples, self.samples_per_task
        return [(a, min(a + k, n)) for a in range(0, n, k)]

    def chunk_path(self, start, stop):
        """The Parquet file of the samples start .. stop-1."""
        return self.folder / CHUNKS / f"part-{start:010d}-{stop:010d}.parquet"

    def missing(self):
        """The tasks whose rows are not on disk yet."""
        return [c for c in self.chunks() if not self.chunk_path(*c).is_file()]

    def write_chunk(self, start, stop, columns):
        """Writes the columns of the samples start .. stop-1 to their Parquet file, atomically."""
        with atomic_path(self.chunk_path(start, stop)) as tmp:
            pq.write_table(pa.table(columns), tmp)

    def combine(self):
        """Write results.parquet from the chunks (all must be there) and return it as a table."""
        tables = [pq.read_table(self.chunk_path(*c)) for c in self.chunks()]
        table = pa.concat_tables(tables).combine_chunks()
        with atomic_path(self.folder / RESULTS) as tmp:
            pq.write_table(table, tmp)
        return table
