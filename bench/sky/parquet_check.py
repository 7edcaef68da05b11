"""Reads a processed sky day's `sky-series.parquet` with pyarrow (issue 29)
and checks it against the day's `sky-series.csv`: the same columns in the
same order, every column's unit in the schema's metadata (the CSV header's
line for it), the same number of rows, every cell equal (numbers exactly,
text, the UTC timestamp to the millisecond, empty CSV cells as nulls, but
an empty `flags` or `condition_note` cell as the empty string: no flag
raised, nothing to note).

    venv=$(bench/venv.sh pyarrow)
    "$venv/bin/python" bench/sky/parquet_check.py OUT     # OUT: a `campanile process` output of a sky day

Exit 0 when everything agrees, 1 otherwise, 2 for bad input.
"""

import csv
import datetime as dt
import sys
from pathlib import Path


def main():
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    out = Path(sys.argv[1])
    pq_path, csv_path = out / "sky-series.parquet", out / "sky-series.csv"
    for p in (pq_path, csv_path):
        if not p.is_file():
            print(f"{p}: no such file (is {out} a processed sky day?)", file=sys.stderr)
            return 2
    import pyarrow
    import pyarrow.parquet as pq

    table = pq.read_table(pq_path)
    meta = {k.decode(): v.decode() for k, v in (table.schema.metadata or {}).items()}
    lines = csv_path.read_text(encoding="utf-8").splitlines()
    docs = {}
    for line in lines:
        if line.startswith("# ") and ": " in line[2:]:
            name, doc = line[2:].split(": ", 1)
            docs[name] = doc
    rows = list(csv.reader(l for l in lines if not l.startswith("#")))
    header, body = rows[0], rows[1:]
    fails = []
    if table.column_names != header:
        fails.append(f"columns differ: {table.column_names} against {header}")
    if table.num_rows != len(body):
        fails.append(f"{table.num_rows} rows against {len(body)}")
    for name in header:
        if meta.get(f"campanile.unit.{name}") != docs.get(name):
            fails.append(f"{name}: unit {meta.get(f'campanile.unit.{name}')!r} against the CSV's {docs.get(name)!r}")
    cells = 0
    for j, name in enumerate(header):
        if name not in table.column_names:
            continue
        col = table.column(name).to_pylist()
        for i, row in enumerate(body):
            want, got = row[j], col[i]
            cells += 1
            if want == "" and name in ("flags", "condition_note"):
                ok = got == ""  # no flag raised, no note: empty text, not a missing value
            elif want == "":
                ok = got is None
            elif isinstance(got, dt.datetime):
                ok = got == dt.datetime.fromisoformat(want.replace("Z", "+00:00"))
            elif isinstance(got, float):
                ok = got == float(want)
            else:
                ok = got == want
            if not ok:
                fails.append(f"row {i + 1} {name}: parquet {got!r} against csv {want!r}")
    types = sorted({str(f.type) for f in table.schema})
    print(f"pyarrow {pyarrow.__version__}: {table.num_rows} rows x {table.num_columns} columns, types {types}; "
          f"{cells} cells compared, {len(fails)} differences; format {meta.get('campanile.format')!r}")
    for f in fails[:20]:
        print("  " + f)
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
