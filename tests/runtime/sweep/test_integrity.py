"""What a sweep merges is proven (runtime/sweep/store.py): a resumed sweep whose chunk files were
corrupted, truncated, duplicated, swapped, emptied, rewritten or replaced by foreign files
recomputes exactly those (naming each) and writes the file of an untouched run; a merge that
finds a bad or missing chunk writes nothing and names the samples and the files."""
import json
import shutil

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from runtime.sweep import cli, runner
from runtime.sweep.runner import SERIAL, run_sweep
from runtime.sweep.spec import load_sweep
from runtime.sweep.store import (METADATA_KEY, RESULTS, SweepIncomplete, SweepStore, _arrays, _digest, chunk_schema,
                                 sweep_digest)
from runtime.sweep.task import run_chunk

from .conftest import SWEEP, write_sweep

#: The small sweep's tasks: 24 samples, 5 per task.
CHUNKS = [(0, 5), (5, 10), (10, 15), (15, 20), (20, 24)]


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    """(spec, folder) of the small sweep run to the end, serially; never modified by a test."""
    folder = tmp_path_factory.mktemp("finished")
    spec = load_sweep(write_sweep(folder))
    run_sweep(spec, folder / "out", scheduler=SERIAL, progress=False)
    return spec, folder / "out"


@pytest.fixture
def copy(finished, tmp_path):
    """(spec, store) of a copy of the finished sweep, without its results file."""
    spec, folder = finished
    out = tmp_path / "out"
    shutil.copytree(folder, out)
    (out / RESULTS).unlink()
    return spec, SweepStore(out, spec, 5)


def part(store, i):
    return store.chunk_path(*CHUNKS[i])


def rewrite(path, change):
    """Rewrite the chunk at `path` with change(columns) applied and a record that matches its new
    rows (as a forger would write it): only the comparison with the sweep's draws can tell."""
    table = pq.read_table(path)
    record = json.loads(table.schema.metadata[METADATA_KEY])
    columns = {name: table.column(name).to_numpy().copy() for name in table.column_names}
    change(columns)
    table = pa.table(columns)
    record["rows"] = _digest(_arrays(table, table.column_names))
    pq.write_table(table.replace_schema_metadata({METADATA_KEY: json.dumps(record).encode()}), path)


def empty(store, i, keep_record):
    metadata = pq.read_schema(part(store, i)).metadata if keep_record else None
    pq.write_table(chunk_schema(store.spec).empty_table().replace_schema_metadata(metadata), part(store, i))


def duplicate(store):
    shutil.copyfile(part(store, 0), part(store, 1))


def swap(store):
    a, b = part(store, 1).read_bytes(), part(store, 2).read_bytes()
    part(store, 1).write_bytes(b)
    part(store, 2).write_bytes(a)


def truncate(store, fraction):
    data = part(store, 1).read_bytes()
    part(store, 1).write_bytes(data[:int(len(data) * fraction)])


def overwrite_middle(store):
    data = bytearray(part(store, 1).read_bytes())
    middle = len(data) // 2
    data[middle:middle + 64] = bytes(64)
    part(store, 1).write_bytes(bytes(data))


def alter_output(store):
    """An outcome value changed, the record kept: the digest of the rows no longer matches."""
    table = pq.read_table(part(store, 1))
    end_x = table.column("end_x").to_numpy().copy()
    end_x[2] += 1e-9
    table = table.set_column(table.column_names.index("end_x"), "end_x", pa.array(end_x))
    pq.write_table(table, part(store, 1))


def alter_input(store):
    def change(columns):
        columns["params.k_S"][2] = np.nextafter(columns["params.k_S"][2], 2.0)
    rewrite(part(store, 1), change)


def shift_samples(store):
    def change(columns):
        columns["sample"] += 1
    rewrite(part(store, 1), change)


def foreign_schema(store):
    pq.write_table(pa.table({"a": [1, 2, 3]}), part(store, 1))


def without_record(store):
    pq.write_table(pq.read_table(part(store, 1)).replace_schema_metadata(None), part(store, 1))


def not_parquet(store):
    part(store, 1).write_text("sample,status\n5,0\n")


def other_sweeps_chunk(store, tmp_path):
    other = load_sweep(write_sweep(tmp_path, SWEEP.replace("seed = 7", "seed = 8"), name="other"))
    run_sweep(other, tmp_path / "other", scheduler=SERIAL, progress=False)
    shutil.copyfile(SweepStore(tmp_path / "other", other, 5).chunk_path(*CHUNKS[1]), part(store, 1))


TAMPERINGS = {
    "emptied (right schema, no record)": (lambda store, tmp: empty(store, 1, keep_record=False), [1],
                                          "integrity record"),
    "emptied (its own record kept)": (lambda store, tmp: empty(store, 1, keep_record=True), [1],
                                      "0 rows for samples 5..9"),
    "duplicated (a copy of the first)": (lambda store, tmp: duplicate(store), [1], "holds samples 0..4"),
    "swapped with the next": (lambda store, tmp: swap(store), [1, 2], "not samples"),
    "truncated to half": (lambda store, tmp: truncate(store, 0.5), [1], "not a readable Parquet file"),
    "truncated to nothing": (lambda store, tmp: truncate(store, 0.0), [1], "not a readable Parquet file"),
    "64 bytes zeroed in the middle": (lambda store, tmp: overwrite_middle(store), [1], ""),
    "an outcome altered": (lambda store, tmp: alter_output(store), [1], "do not match the digest"),
    "an input altered by one ulp, digests forged": (lambda store, tmp: alter_input(store), [1],
                                                    "params.k_S values that are not this sweep's"),
    "sample ids shifted, digests forged": (lambda store, tmp: shift_samples(store), [1], "sample ids"),
    "a foreign schema": (lambda store, tmp: foreign_schema(store), [1], "columns are not this sweep's"),
    "the rows without their record": (lambda store, tmp: without_record(store), [1], "no integrity record"),
    "not Parquet": (lambda store, tmp: not_parquet(store), [1], "not a readable Parquet file"),
    "another sweep's chunk of the same range": (other_sweeps_chunk, [1], "names another sweep"),
}


@pytest.mark.parametrize("tamper", TAMPERINGS)
def test_a_resumed_sweep_recomputes_every_bad_chunk_it_names_and_writes_the_untouched_file(finished, copy,
                                                                                           tmp_path, tamper):
    spec, store = copy
    change, bad, reason = TAMPERINGS[tamper]
    change(store, tmp_path)
    notices = []
    table = run_sweep(spec, store.folder, scheduler=SERIAL, progress=False, notify=notices.append)
    assert (store.folder / RESULTS).read_bytes() == (finished[1] / RESULTS).read_bytes()
    assert table.column("sample").to_pylist() == list(range(spec.samples))
    assert [n.split(":", 1)[0] for n in notices] == [str(part(store, i)) for i in bad]
    assert all(n.endswith("; recomputing it") for n in notices)
    assert reason in notices[0]


@pytest.mark.parametrize("tamper", TAMPERINGS)
def test_the_merge_refuses_a_bad_chunk_naming_the_file_and_the_samples_and_writes_nothing(copy, tmp_path, tamper):
    spec, store = copy
    change, bad, reason = TAMPERINGS[tamper]
    change(store, tmp_path)
    with pytest.raises(SweepIncomplete) as caught:
        store.combine()
    assert not (store.folder / RESULTS).exists()
    assert caught.value.missing == [(5, 15)] if bad == [1, 2] else caught.value.missing == [(5, 10)]
    assert [path for path, _ in caught.value.bad] == [part(store, i) for i in bad]
    message = str(caught.value)
    assert part(store, bad[0]).name in message and reason in message
    assert ("samples 5..14" if bad == [1, 2] else "samples 5..9") in message


def test_the_merge_names_missing_chunks_as_sample_ranges(copy):
    spec, store = copy
    part(store, 1).unlink()
    part(store, 4).unlink()
    with pytest.raises(SweepIncomplete, match=r"9 samples have no verified rows \(samples 5..9, samples 20..23\)"):
        store.combine()
    assert not (store.folder / RESULTS).exists()


def test_an_untouched_folder_verifies_and_merges_to_the_same_file(finished, copy):
    spec, store = copy
    assert store.verify() == ([], [])
    store.combine()
    assert (store.folder / RESULTS).read_bytes() == (finished[1] / RESULTS).read_bytes()


def test_every_chunk_records_the_sweep_its_range_and_the_digests_of_its_inputs_and_rows(finished):
    spec, folder = finished
    store = SweepStore(folder, spec, 5)
    other = load_sweep(write_sweep(folder.parent, SWEEP.replace("seed = 7", "seed = 8"), name="other"))
    assert sweep_digest(other) != sweep_digest(spec)
    for a, b in CHUNKS:
        table = pq.read_table(store.chunk_path(a, b))
        record = json.loads(table.schema.metadata[METADATA_KEY])
        assert (record["sweep"], record["start"], record["stop"]) == (sweep_digest(spec), a, b)
        inputs = ["sample"] + [q.name for q in spec.quantities]
        assert record["inputs"] == _digest(_arrays(table, inputs))
        assert record["rows"] == _digest(_arrays(table, table.column_names))
    results = pq.read_schema(folder / RESULTS).metadata[METADATA_KEY]
    assert json.loads(results) | {"rows": None} == {"sweep": sweep_digest(spec), "samples": 24, "rows": None}


def test_a_task_computes_the_columns_of_the_chunk_schema(spec):
    assert pa.table(run_chunk(spec, 3, 6)).schema == chunk_schema(spec)


def test_rows_of_a_worker_that_draws_other_inputs_are_not_written_and_the_command_fails(
        finished, tmp_path, monkeypatch, capsys):
    """A worker running another version of the package would draw other inputs for the same
    samples: its rows must not reach the results."""
    path = write_sweep(tmp_path)

    def other_draws(spec, a, b):
        columns = run_chunk(spec, a, b)
        if a == 5:
            columns["torque.u_Y_scale"] = columns["torque.u_Y_scale"] * 1.0001
        return columns

    monkeypatch.setattr(runner, "run_chunk", other_draws)
    command = [str(path), "--out", str(tmp_path / "out"), "--scheduler", "serial", "--samples-per-task", "5",
               "--no-progress"]
    assert cli.main(command) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2
    assert "the rows computed for samples 5..9 hold torque.u_Y_scale values that are not this sweep's" in err[0]
    assert err[1].startswith("error: ") and "5 samples have no verified rows (samples 5..9)" in err[1]
    assert not (tmp_path / "out" / RESULTS).exists()
    assert not SweepStore(tmp_path / "out", load_sweep(path), 5).chunk_path(5, 10).exists()
    monkeypatch.setattr(runner, "run_chunk", run_chunk)
    assert cli.main(command) == 1          # some of the file's samples fail: their rows say so
    assert (tmp_path / "out" / RESULTS).read_bytes() == (finished[1] / RESULTS).read_bytes()


def test_the_cli_names_a_bad_chunk_recomputes_it_and_exits_as_an_untouched_run(tmp_path, capsys):
    path = write_sweep(tmp_path, SWEEP.replace("normal = [1.0, 0.6]", "uniform = [0.9, 1.1]"))
    command = [str(path), "--out", str(tmp_path / "out"), "--scheduler", "serial", "--no-progress"]
    assert cli.main(command) == 0
    whole = (tmp_path / "out" / RESULTS).read_bytes()
    store = SweepStore(tmp_path / "out", load_sweep(path), 5)
    duplicate(store)
    capsys.readouterr()
    assert cli.main(command) == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"warning: {part(store, 1)}: its integrity record says it holds samples 0..4, not samples "
                   "5..9; recomputing it"]
    assert (tmp_path / "out" / RESULTS).read_bytes() == whole


def test_no_flipped_byte_gives_a_chunk_that_verifies_with_other_rows(copy):
    """Every 11th byte of a chunk file inverted, one at a time: the file fails verification, or
    (a byte of the footer's statistics or padding) it still holds exactly its rows."""
    spec, store = copy
    path = part(store, 1)
    original = path.read_bytes()
    rows, _ = store.read_chunk(*CHUNKS[1])
    digest = _digest(_arrays(rows, rows.column_names))
    refused = 0
    for offset in range(0, len(original), 11):
        flipped = bytearray(original)
        flipped[offset] ^= 0xFF
        path.write_bytes(bytes(flipped))
        table, why = store.read_chunk(*CHUNKS[1])
        if why is None:
            assert _digest(_arrays(table, table.column_names)) == digest, f"byte {offset}"
        refused += why is not None
    assert refused > len(original) // 11 // 2
