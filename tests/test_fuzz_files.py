"""Files with random damage (issue 42): every reader either returns what it read or raises
ValueError naming the file -- never another exception, never a hang.  Each example takes a good
fit record or sweep file, changes one item (an attribute or a dataset: deleted, replaced by
text, an array, NaN, a huge or negative number, deep JSON) and reads it back."""

import shutil

import h5py
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import shellbvp as sb
from shellbvp.cli import main

REPLACEMENTS = st.sampled_from([
    None,  # delete
    "text", "False", "", "[" * 5000, "{\"a\": 1}", np.nan, np.inf, -1.0, 0.0, 1e300, 99, True,
    np.array([1, 2, 3]), np.array(["x", "y"], dtype=object), np.zeros((2, 2)),
])


def _items(path):
    out = []
    with h5py.File(path, "r") as h:
        def visit(name, obj):
            out.append(("dataset", name, None) if isinstance(obj, h5py.Dataset) else ("group", name, None))
            for a in obj.attrs:
                out.append(("attr", name, a))
        for a in h.attrs:
            out.append(("attr", "", a))
        h.visititems(visit)
    return out


def _damage(path, item, value):
    kind, name, attr = item
    with h5py.File(path, "r+") as h:
        obj = h[name] if name else h
        if kind == "attr":
            if value is None:
                del obj.attrs[attr]
            elif isinstance(value, np.ndarray) and value.dtype == object:
                obj.attrs.create(attr, value, dtype=h5py.string_dtype())
            else:
                obj.attrs[attr] = value
        else:
            parent, leaf = (name.rsplit("/", 1) + [""])[:2] if "/" in name else ("", name)
            del h[name]
            if value is None:
                return
            g = h[parent] if parent else h
            if isinstance(value, np.ndarray) and value.dtype == object:
                g.create_dataset(leaf, data=value, dtype=h5py.string_dtype())
            elif isinstance(value, str):
                g.create_dataset(leaf, data=value, dtype=h5py.string_dtype())
            else:
                g.create_dataset(leaf, data=value)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    from shellbvp.sweeps import sweep

    d = tmp_path_factory.mktemp("good")
    fit = d / "fit.h5"
    assert main(["fit", "--example", "--preset", "fit", "--radius", "0.3mm", "-o", str(fit)]) == 0
    grid = d / "grid.h5"
    sweep(sb.Scene.preset("base"), {"beta": [0.005, 0.01]}, delta_max=0.1, out=grid, workers=1, deltas=[0.05, 0.1],
          estimate_error=False)
    return {"fit": (fit, _items(fit), sb.read_fit), "sweep": (grid, _items(grid), sb.read_sweep)}


@settings(max_examples=60, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(kind=st.sampled_from(["fit", "sweep"]), pick=st.integers(0, 10_000), value=REPLACEMENTS)
def test_a_damaged_file_reads_or_is_refused_in_one_line(files, tmp_path, kind, pick, value):
    good, items, read = files[kind]
    bad = tmp_path / f"bad-{kind}.h5"
    shutil.copy(good, bad)
    item = items[pick % len(items)]
    try:
        _damage(bad, item, value)
    except (TypeError, ValueError, OSError):
        return  # h5py cannot store this value there: nothing to read
    try:
        read(bad)
    except ValueError as exc:
        assert "bad-" in str(exc), (item, value, exc)


# -- batches: folders of anything -------------------------------------------------------------------
LINES = st.one_of(
    st.text(max_size=60),
    st.lists(st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.integers(-10**20, 10**20),
                       st.sampled_from(["", "nan", "1,5", "5_0", "\u00b5N", "(mm)", "=HYPERLINK(\"x\")", "\x1b[2J"])),
             min_size=1, max_size=4).map(lambda cells: ",".join(str(c) for c in cells)),
)
CONTENTS = st.one_of(
    st.binary(max_size=300),
    st.lists(LINES, max_size=30).map(lambda lines: "\n".join(lines).encode("utf-8", "surrogatepass")),
)


@pytest.fixture(scope="module")
def good_record(tmp_path_factory):
    """The shipped example (a Lepidium-like record) and its fit on its own."""
    from shellbvp.fitting import example_data_path

    path = tmp_path_factory.mktemp("good") / "good.csv"
    shutil.copy(example_data_path(), path)
    (alone,) = sb.fit_files(sb.Scene.preset("fit"), [str(path)], R_L=0.3e-3)
    assert alone.status == "ok"
    return path, alone.result.mu_H


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(contents=st.lists(CONTENTS, min_size=1, max_size=4), suffixes=st.lists(
    st.sampled_from([".csv", ".tsv", ".txt", ".dat", ".jpk-force"]), min_size=4, max_size=4))
def test_a_batch_of_random_files_costs_the_good_one_nothing(good_record, tmp_path_factory, contents, suffixes):
    """Every file gets its row (ok, failed or error; an error row one line naming the file), the
    table is written, and the good file's result is its result alone (issue 42, item 7)."""
    from shellbvp.batch import write_table

    good, mu_alone = good_record
    folder = tmp_path_factory.mktemp("batch")
    paths = []
    for k, data in enumerate(contents):
        p = folder / f"junk{k}{suffixes[k]}"
        p.write_bytes(data)
        paths.append(str(p))
    paths.insert(len(paths) // 2, str(good))
    rows = sb.fit_files(sb.Scene.preset("fit"), paths, R_L=0.3e-3)
    assert [r.file for r in rows] == paths
    for r in rows:
        assert r.status in ("ok", "failed", "error")
        if r.status == "error":
            assert "\n" not in r.message and r.message
    (mine,) = [r for r in rows if r.file == str(good)]
    assert mine.status == "ok" and mine.result.mu_H == pytest.approx(mu_alone, rel=1e-9)
    write_table(folder / "table.csv", rows)
    assert (folder / "table.csv").read_text().count("\n") == len(rows) + 1
