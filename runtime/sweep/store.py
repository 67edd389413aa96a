"""The output folder of a sweep: written chunk by chunk, so that an interrupted sweep resumes, and
verified chunk by chunk, so that what it merges is provably this sweep's rows.

    OUT/sweep.json                   what the sweep is (the resume check) and its task size
    OUT/chunks/part-A-B.parquet      the rows of samples A..B-1, each file written atomically
    OUT/results.parquet              all rows, in sample order, once every chunk is there

A chunk file exists only complete (written to a temporary name, then renamed), so after a
kill the folder holds whole chunks and nothing else that counts: a restart computes the
missing ones only.  The rows of a sample depend on the sweep file and the sample index only,
so the resumed results equal an uninterrupted run's byte for byte.

Every chunk carries, in its Parquet key-value metadata (key `METADATA_KEY`, JSON), the sweep's
digest, its sample range, the digest of its samples' inputs and the digest of all its rows.  A
chunk is trusted only if its columns are this sweep's, its metadata names this sweep and this
range, its rows are the samples A..B-1 in order with the inputs the sweep file draws for them
(redrawn here, compared bit for bit), and its rows match the digest it was written with.  A
file that fails is named and recomputed when a sweep resumes, and never merged: the merge
either writes every sample exactly once or raises `SweepIncomplete`.
"""
import hashlib
import json
import pathlib

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from ..atomic import atomic_path, write_text
from .spec import MAX_SAMPLES, quantity_values
from .task import column_names

MANIFEST = "sweep.json"
RESULTS = "results.parquet"
CHUNKS = "chunks"
#: Key of the integrity record in the Parquet metadata of every chunk and of results.parquet.
METADATA_KEY = b"runtime.sweep"
#: Bad chunk files named in one message at most (the rest are counted).
NAMED_AT_MOST = 5


class SweepIncomplete(Exception):
    """The merge found samples without a verified chunk; `missing` (start, stop) ranges and `bad`
    (path, reason) pairs say which."""

    def __init__(self, folder, missing, bad):
        self.missing, self.bad = missing, bad
        n = sum(b - a for a, b in missing)
        ranges = ", ".join(_samples(a, b) for a, b in missing[:NAMED_AT_MOST])
        more = f" and {len(missing) - NAMED_AT_MOST} more ranges" if len(missing) > NAMED_AT_MOST else ""
        text = f"{folder}: the sweep is incomplete, {n} samples have no verified rows ({ranges}{more})"
        if bad:
            named = "; ".join(f"{path.name}: {why}" for path, why in bad[:NAMED_AT_MOST])
            more = f"; and {len(bad) - NAMED_AT_MOST} more" if len(bad) > NAMED_AT_MOST else ""
            text += f"; bad chunk files in {bad[0][0].parent}: {named}{more}"
        super().__init__(text + "; nothing was merged (rerun the same command to compute them)")


class BadRows(ValueError):
    """Rows computed for a task that are not the rows of its samples (not written)."""


def _samples(a, b):
    return f"sample {a}" if b - a == 1 else f"samples {a}..{b - 1}"


def sweep_digest(spec):
    """SHA-256 of what makes the sweep (its identity, as the resume check compares it)."""
    text = json.dumps(spec.identity(), sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()


def chunk_schema(spec):
    """The Arrow schema of a chunk's rows (without metadata)."""
    types = {"sample": pa.int64(), "status": pa.int32(), "steps_done": pa.int64()}
    if hasattr(spec, "arrow_types"):
        types.update(spec.arrow_types())
    return pa.schema([(name, types.get(name, pa.float64())) for name in column_names(spec)])


def _digest(arrays):
    """SHA-256 of named arrays: names, dtypes, lengths and bytes."""
    h = hashlib.sha256()
    for name, array in arrays:
        array = np.ascontiguousarray(array)
        h.update(f"{name}\0{array.dtype.str}\0{array.size}\0".encode())
        h.update(array.tobytes())
    return h.hexdigest()


def _arrays(table, names):
    return [(name, table.column(name).to_numpy()) for name in names]


class SweepStore:
    """The folder `folder` of the sweep `spec`, split into tasks of `samples_per_task` samples."""

    def __init__(self, folder, spec, samples_per_task):
        self.folder = pathlib.Path(folder)
        self.spec = spec
        self.samples_per_task = samples_per_task
        self.digest = sweep_digest(spec)
        self.schema = chunk_schema(spec)
        self._inputs = ("sample",) + tuple(q.name for q in spec.quantities)
        self._drawn = {}                # (start, stop) -> digest of the inputs the sweep file draws

    @classmethod
    def open(cls, folder, spec, choose_samples_per_task):
        """Create the folder for `spec`, or reopen it to resume; refuses a folder of another sweep.

        `choose_samples_per_task()` is called only for a new folder (a resumed sweep keeps its
        tasks, although its rows would be the same with any split), before anything is written.
        """
        folder = pathlib.Path(folder)
        if folder.exists() and not folder.is_dir():
            raise ValueError(f"--out: {folder} exists and is not a folder")
        for parent in folder.parents:
            if parent.exists():
                if not parent.is_dir():
                    raise ValueError(f"--out: {parent} is a file, not a folder, so {folder} cannot be made")
                break
        identity = json.loads(json.dumps(spec.identity()))
        manifest = folder / MANIFEST
        if manifest.is_file():
            per_task = _read_manifest(manifest, identity)
            (folder / CHUNKS).mkdir(exist_ok=True)
            return cls(folder, spec, per_task)
        if folder.is_dir() and any(folder.iterdir()):
            raise ValueError(f"--out: {folder} is not empty and holds no sweep; choose another folder")
        per_task = int(choose_samples_per_task())
        (folder / CHUNKS).mkdir(parents=True, exist_ok=True)
        write_text(manifest, json.dumps({"sweep": spec.name, "source": spec.source, "samples_per_task": per_task,
                                         "digest": sweep_digest(spec), "identity": identity}, indent=1) + "\n")
        return cls(folder, spec, per_task)

    def chunks(self):
        """(start, stop) of every task, in sample order."""
        n, k = self.spec.samples, self.samples_per_task
        return [(a, min(a + k, n)) for a in range(0, n, k)]

    def chunk_path(self, start, stop):
        """The Parquet file of the samples start .. stop-1."""
        return self.folder / CHUNKS / f"part-{start:010d}-{stop:010d}.parquet"

    def verify(self):
        """(todo, bad): the tasks to compute (no chunk file, or one that fails verification) and
        the (path, reason) of every chunk file that fails."""
        todo, bad = [], []
        for a, b in self.chunks():
            path = self.chunk_path(a, b)
            if not path.exists():
                todo.append((a, b))
                continue
            _, why = self.read_chunk(a, b)
            if why is not None:
                todo.append((a, b))
                bad.append((path, why))
        return todo, bad

    def missing(self):
        """The tasks whose verified rows are not on disk yet."""
        return self.verify()[0]

    def write_chunk(self, start, stop, columns):
        """Write the rows `columns` ({name: array}, as `task.run_chunk` returns them) of samples
        start..stop-1, after checking that they are these samples' rows with this sweep's inputs
        (a worker running another version of this package would draw others): raises BadRows."""
        table = pa.table(columns)
        why = self._check_rows(table, start, stop)
        if why is not None:
            raise BadRows(f"the rows computed for {_samples(start, stop)} hold {why}; not written")
        record = {"sweep": self.digest, "start": start, "stop": stop, "inputs": self._drawn_digest(start, stop),
                  "rows": _digest(_arrays(table, table.column_names))}
        table = table.replace_schema_metadata({METADATA_KEY: json.dumps(record).encode()})
        with atomic_path(self.chunk_path(start, stop)) as tmp:
            pq.write_table(table, tmp)

    def read_chunk(self, start, stop):
        """(table, None) for a chunk file that passes verification, else (None, what is wrong)."""
        path = self.chunk_path(start, stop)
        try:
            with pq.ParquetFile(path) as file:
                schema, table = file.schema_arrow, file.read()
        except Exception as exc:    # noqa: BLE001  (any failure to read the file makes it bad)
            return None, f"not a readable Parquet file ({type(exc).__name__}: {exc})".replace("\n", " ")
        if not schema.remove_metadata().equals(self.schema):
            return None, f"its columns are not this sweep's ({_schema_difference(schema, self.schema)})"
        try:
            record = json.loads((schema.metadata or {})[METADATA_KEY])
            sweep, rng, inputs, rows = record["sweep"], (record["start"], record["stop"]), record["inputs"], \
                record["rows"]
        except (KeyError, TypeError, ValueError):
            return None, "it carries no integrity record of a sweep (not written by this sweep)"
        if sweep != self.digest:
            return None, "its integrity record names another sweep"
        if rng != (start, stop):
            return None, f"its integrity record says it holds {_samples(*rng)}, not {_samples(start, stop)}"
        why = self._check_rows(table, start, stop)
        if why is not None:
            return None, f"it holds {why}"
        if inputs != self._drawn_digest(start, stop):
            return None, "its integrity record's inputs digest is not that of this sweep's draws"
        if _digest(_arrays(table, table.column_names)) != rows:
            return None, "its rows do not match the digest they were written with (the file was altered)"
        return table.replace_schema_metadata(None), None

    def _drawn_digest(self, start, stop):
        key = (start, stop)
        if key not in self._drawn:
            self._drawn[key] = _digest(self._draw(start, stop))
        return self._drawn[key]

    def _draw(self, start, stop):
        values = quantity_values(self.spec, start, stop)
        return [("sample", np.arange(start, stop, dtype=np.int64))] + [(q, values[q]) for q in self._inputs[1:]]

    def _check_rows(self, table, start, stop):
        """What is wrong with `table` as the rows of samples start..stop-1 (None: nothing)."""
        if not table.schema.remove_metadata().equals(self.schema):
            return f"columns that are not this sweep's ({_schema_difference(table.schema, self.schema)})"
        if table.num_rows != stop - start:
            return f"{table.num_rows} rows for {_samples(start, stop)} ({stop - start} expected)"
        nulls = [name for name in table.column_names if table.column(name).null_count]
        if nulls:
            return f"missing values in {', '.join(nulls)}"
        if _digest(_arrays(table, self._inputs)) == self._drawn_digest(start, stop):
            return None
        for name, drawn in self._draw(start, stop):
            held = table.column(name).to_numpy()
            if held.tobytes() != np.ascontiguousarray(drawn).tobytes():
                row = int(np.flatnonzero(held.view(np.uint64) != drawn.view(np.uint64))[0]) \
                    if name != "sample" else int(np.flatnonzero(held != drawn)[0])
                what = "sample ids" if name == "sample" else f"{name} values"
                return (f"{what} that are not this sweep's (row {row}: {held[row]}, "
                        f"expected {drawn[row]} for sample {start + row})")
        return "inputs that do not match this sweep's draws"

    def combine(self):
        """Write results.parquet from the chunks and return it as a table: only if every chunk
        passes verification, so that every sample appears exactly once; else SweepIncomplete."""
        tables, missing, bad = [], [], []
        for a, b in self.chunks():
            path = self.chunk_path(a, b)
            table, why = self.read_chunk(a, b) if path.exists() else (None, None)
            if table is None:
                missing.append((a, b))
                if why is not None:
                    bad.append((path, why))
            else:
                tables.append(table)
        if missing:
            raise SweepIncomplete(self.folder, _merge_ranges(missing), bad)
        table = pa.concat_tables(tables).combine_chunks()
        record = {"sweep": self.digest, "samples": self.spec.samples,
                  "rows": _digest(_arrays(table, table.column_names))}
        table = table.replace_schema_metadata({METADATA_KEY: json.dumps(record).encode()})
        with atomic_path(self.folder / RESULTS) as tmp:
            pq.write_table(table, tmp)
        return table


def _read_manifest(manifest, identity):
    """The task size recorded in `manifest`, after checking that it is this sweep's."""
    try:
        data = json.loads(manifest.read_text(encoding="utf-8"))
        same, per_task = data["identity"] == identity, data["samples_per_task"]
    except (ValueError, KeyError, TypeError) as exc:
        raise ValueError(f"--out: {manifest} is not a sweep manifest ({type(exc).__name__}: {exc}); "
                         "choose another folder") from None
    if not same:
        raise ValueError(f"--out: {manifest.parent} holds the results of a different sweep (another sweep "
                         "file, seed or sample count); choose another folder")
    if isinstance(per_task, bool) or not isinstance(per_task, int) or not 1 <= per_task <= MAX_SAMPLES:
        raise ValueError(f"--out: {manifest}: samples_per_task: expected a whole number from 1 to {MAX_SAMPLES}, "
                         f"got {per_task!r} (the file was edited); choose another folder")
    return per_task


def _merge_ranges(ranges):
    merged = []
    for a, b in ranges:
        if merged and merged[-1][1] == a:
            merged[-1] = (merged[-1][0], b)
        else:
            merged.append((a, b))
    return merged


def _schema_difference(got, expected):
    got_types = {f.name: f.type for f in got}
    exp_types = {f.name: f.type for f in expected}
    parts = []
    missing = [n for n in exp_types if n not in got_types]
    extra = [n for n in got_types if n not in exp_types]
    wrong = [f"{n} is {got_types[n]}, expected {exp_types[n]}" for n in exp_types
             if n in got_types and got_types[n] != exp_types[n]]
    if missing:
        parts.append(f"missing {', '.join(missing[:NAMED_AT_MOST])}" + (" ..." if len(missing) > NAMED_AT_MOST else ""))
    if extra:
        parts.append(f"unexpected {', '.join(extra[:NAMED_AT_MOST])}" + (" ..." if len(extra) > NAMED_AT_MOST else ""))
    parts += wrong[:NAMED_AT_MOST]
    if not parts:
        parts.append("the same names and types in another order or nullability")
    return "; ".join(parts)
