"""Reading hemotree's files in Python: the one way every script in scripts/ and bench/ reads them.

    import sys
    sys.path.insert(0, "/path/to/hemotree/python")
    import hemotree_io as hio

    net = hio.read_network("net.json")       # a vnet network: net.vessels, net.nodes (DataFrames)
    facts = hio.read_summary("run")          # summary.json as a dict ("vessels": a list of dicts)
    vessels = hio.read_vessels("run")        # vessels.csv as a DataFrame, one row per vessel
    probes = hio.read_probes("run")          # probes.csv as a DataFrame, the time first

Either form of either file: a network in JSON or HDF5 (net.h5), a run written as text or with
`hemosolve --format h5` (results.h5 in the folder); the same DataFrames and dicts either way
(HDF5 needs h5py: Debian python3-h5py).
    p = hio.probe_column(probes, "p", 1, 0.5)

A run's folder is what `hemosolve NET --out DIR` writes (docs/solver.md); a reader given a
folder opens the file of its name there, given a file opens that file. The tables keep the
names of their CSV headers and hold every number as the double its text reads as
(`float(text)`, so the same as summary.json's); an empty field (hemotree's null) is NaN.

Besides these, the JSON of `vstats --json` (read_network_stats) and of `vprune
--profile-report` (read_profile_report).

Errors: a file that is not what it should be raises FormatError (a ValueError), its one-line
message naming the file; JSON that does not parse raises json.JSONDecodeError (a ValueError)
and a file that cannot be opened OSError, as json.load and open do. The JSON readers need the
standard library only; the tables need numpy and pandas (Debian: python3-numpy,
python3-pandas), and without them raise MissingDependency, one line saying what to install.
"""
import csv
import io
import json
import re
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["FormatError", "MissingDependency", "Network", "read_network", "read_summary",
           "read_vessels", "read_probes", "parse_probe_name", "probe_column",
           "read_network_stats", "read_profile_report", "TEXT_COLUMNS"]

# vessels.csv's columns of words (the others hold numbers).
TEXT_COLUMNS = ("class", "model")


class FormatError(ValueError):
    """A file that is not what it should be; the message is one line naming the file."""


class MissingDependency(ImportError):
    """numpy, pandas or h5py is not installed; the message is one line saying what to install."""


def _h5py():
    try:
        import h5py
    except ImportError:
        raise MissingDependency("reading hemotree's HDF5 files needs h5py "
                                "(Debian: apt-get install python3-h5py)") from None
    return h5py


_HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"


def _is_hdf5(path):
    with open(path, "rb") as f:
        return f.read(8) == _HDF5_SIGNATURE


def _text(dataset):
    """One text of a hemotree HDF5 file (a one-row string dataset, or a scalar)."""
    value = dataset[()] if dataset.shape == () else dataset[0]
    return value.decode("utf-8") if isinstance(value, bytes) else str(value)


def _h5_columns(group, categories=True):
    """A group of one-dimensional datasets as a dict of arrays, enumerations as categories
    (CATEGORIES) or their labels."""
    pd = _pandas()
    h5py = _h5py()
    columns = {}
    for name, dataset in group.items():
        values = dataset[:]
        labels = h5py.check_enum_dtype(dataset.dtype)
        if labels is not None:
            by_code = {code: label for label, code in labels.items()}
            codes = [by_code[c] for c in range(max(by_code) + 1)] if by_code else []
            values = pd.Categorical.from_codes(values.astype(int), categories=codes)
            if not categories:
                values = values.astype(str)
        columns[name] = values
    return columns


def _pandas():
    try:
        import pandas
    except ImportError:
        raise MissingDependency("reading hemotree's tables needs pandas "
                                "(Debian: apt-get install python3-pandas)") from None
    return pandas


def _file(path, name):
    """PATH itself, or PATH/NAME where PATH is a folder."""
    path = Path(path)
    return path / name if path.is_dir() else path


# ---- networks ---------------------------------------------------------------------------

@dataclass
class Network:
    """A vnet network (docs/network-format.md), as read_network returns it.

    vessels     one row per vessel in the file's order; a column per member any vessel has
                (id, from, to, length, diameter, ...), NaN where a vessel lacks it; `outlet`
                holds each vessel's outlet object (a dict) or NaN
    nodes       one row per node (id, and x, y, z where the file has coordinates); a file
                without `nodes` gets the vessels' from/to ids, in order of appearance
    blood, inlet, provenance   the file's objects ({} where absent)
    boundaries  the file's node boundaries, a list of dicts as written ([] where absent)
    version     the format version
    other       any other top-level member, as written
    """
    vessels: object
    nodes: object
    version: int
    blood: dict = field(default_factory=dict)
    inlet: dict = field(default_factory=dict)
    boundaries: list = field(default_factory=list)
    provenance: dict = field(default_factory=dict)
    other: dict = field(default_factory=dict)


def read_network(path):
    """The vnet network in the JSON file PATH, as a Network (per-vessel and per-node columns
    as DataFrames, the rest as dicts). The whole document is held in memory: fine for the
    pruned networks, too much for a full tree of millions of vessels (about 10 GB)."""
    pd = _pandas()
    path = Path(path)
    if _is_hdf5(path):
        return _read_network_hdf5(path)
    with open(path) as f:
        doc = json.load(f)
    if not isinstance(doc, dict) or doc.get("format") != "vnet":
        raise FormatError(f"{path}: not a vnet network (no \"format\": \"vnet\")")
    version = doc.get("version")
    if isinstance(version, bool) or not isinstance(version, int):
        raise FormatError(f"{path}: no integer \"version\"")
    vessels = doc.get("vessels")
    if not isinstance(vessels, list) or not all(isinstance(v, dict) for v in vessels):
        raise FormatError(f"{path}: \"vessels\" is not a list of objects")
    nodes = doc.get("nodes")
    if nodes is None:
        ids = dict.fromkeys(i for v in vessels for i in (v.get("from"), v.get("to")))
        node_table = pd.DataFrame({"id": pd.array(list(ids), dtype="int64")})
    elif isinstance(nodes, list) and all(isinstance(n, dict) for n in nodes):
        node_table = pd.DataFrame.from_records(nodes) if nodes else pd.DataFrame({"id": []})
    else:
        raise FormatError(f"{path}: \"nodes\" is not a list of objects")
    members = {}
    for key in ("blood", "inlet", "provenance"):
        value = doc.get(key, {})
        if not isinstance(value, dict):
            raise FormatError(f"{path}: \"{key}\" is not an object")
        members[key] = value
    boundaries = doc.get("boundaries", [])
    if not isinstance(boundaries, list) or not all(isinstance(b, dict) for b in boundaries):
        raise FormatError(f"{path}: \"boundaries\" is not a list of objects")
    known = {"format", "version", "vessels", "nodes", "blood", "inlet", "provenance", "boundaries"}
    return Network(vessels=pd.DataFrame.from_records(vessels) if vessels else pd.DataFrame(),
                   nodes=node_table, version=version, boundaries=boundaries,
                   other={k: v for k, v in doc.items() if k not in known}, **members)


def _read_network_hdf5(path):
    """read_network's Network from the HDF5 form (docs/network-format.md): the same columns as
    the JSON form gives (`from`, `to` as node ids, `class` as words, `outlet` as dicts)."""
    pd = _pandas()
    import numpy as np
    h5py = _h5py()
    with h5py.File(path, "r") as f:
        fmt = f.attrs.get("format")
        if (fmt.decode() if isinstance(fmt, bytes) else fmt) != "vnet":
            raise FormatError(f"{path}: not a vnet network (no attribute format = \"vnet\")")
        nodes = pd.DataFrame(_h5_columns(f["nodes"]))
        columns = _h5_columns(f["vessels"], categories=False)
        ids = nodes["id"].to_numpy()
        columns["from"] = ids[columns.pop("from_node")]
        columns["to"] = ids[columns.pop("to_node")]
        order = ["id", "from", "to", "length", "diameter", "distal_diameter", "wall_thickness",
                 "youngs_modulus", "generation", "class", "beta", "reference_pressure"]
        vessels = pd.DataFrame({k: columns[k] for k in order if k in columns})
        if "outlets" in f:
            out = _h5_columns(f["outlets"], categories=False)
            used = {"RCR": ("R1", "C", "R2", "p_out"), "R": ("R", "p_out"), "reflection": ("coefficient",)}
            outlet = np.full(len(vessels), np.nan, dtype=object)
            for k, v in enumerate(out["vessel"]):
                kind = out["type"][k]
                if kind not in used:
                    raise FormatError(f"{path}: /outlets/type row {k}: unknown outlet type {kind!r}")
                outlet[v] = {"type": kind, **{name: float(out[name][k]) for name in used[kind]}}
            vessels["outlet"] = outlet
        texts = {k: json.loads(_text(f[k])) for k in ("blood", "inlet", "provenance", "boundaries", "extra")
                 if k in f}
        if "version" not in f.attrs:
            raise FormatError(f"{path}: no attribute version")
        version = int(f.attrs["version"])
    return Network(vessels=vessels, nodes=nodes, version=version, blood=texts.get("blood", {}),
                   inlet=texts.get("inlet", {}), boundaries=texts.get("boundaries", []),
                   provenance=texts.get("provenance", {}), other=texts.get("extra", {}))


def _results_h5(path):
    """results.h5 of a run: PATH itself when it is that file, else PATH/results.h5 when the
    folder holds one; None for a run written as text. FormatError for an HDF5 file that is not
    a run's results (a network given by mistake)."""
    path = Path(path)
    if path.is_dir():
        path = path / "results.h5"
        if not path.exists():
            return None
    elif not (path.exists() and _is_hdf5(path)):
        return None
    h5py = _h5py()
    with h5py.File(path, "r") as f:
        fmt = f.attrs.get("format")
    if (fmt.decode() if isinstance(fmt, bytes) else fmt) != "hemotree-results":
        raise FormatError(f"{path}: not a hemosolve results.h5 (its format attribute is {fmt!r})")
    return path


# ---- summary.json -----------------------------------------------------------------------

# hemosolve writes summary.json as the run's facts, one member a line, then this line and
# one vessel a line (docs/solver.md).
_VESSELS_LINE = ' "vessels": ['


def read_summary(path, vessels=True):
    """summary.json of a run (PATH: the run's folder or the file) as a dict, as json.load
    reads it: the run's facts, and "vessels", a list of one dict per vessel.

    vessels=False reads the facts alone: in hemosolve's layout (the facts one a line, then
    the vessels) only the lines before the vessels are parsed, so a full tree's 3.8 million
    vessels cost nothing, and what follows them (e.g. "statistics") is not read either;
    a summary of another layout is read whole and its "vessels" left out."""
    results = _results_h5(path)
    if results is not None:
        h5py = _h5py()
        with h5py.File(results, "r") as f:
            if "summary" not in f:
                raise FormatError(f"{results}: not a hemosolve results.h5 (no /summary)")
            summary = json.loads(_text(f["summary"]))
            if "boundaries" in f:
                # summary.json's list as the text form has it: a member absent where NaN
                # (hematocrit at outlets), enumerations as their words, integers as ints.
                columns = _h5_columns(f["boundaries"], categories=False)
                names = list(columns)
                rows = len(columns[names[0]]) if names else 0
                entries = []
                for i in range(rows):
                    entry = {}
                    for name in names:
                        x = columns[name][i]
                        if isinstance(x, float) and x != x:
                            continue
                        entry[name] = x.item() if hasattr(x, "item") else x
                    entries.append(entry)
                summary["boundaries"] = entries
        if vessels:
            table = read_vessels(results)
            summary["vessels"] = [{k: (None if isinstance(x, float) and x != x else x) for k, x in row.items()}
                                  for row in table.astype(object).to_dict("records")]
        return summary
    path = _file(path, "summary.json")
    if not vessels:
        head = _summary_head(path)
        if head is not None:
            return head
    with open(path) as f:
        summary = json.load(f)
    if not isinstance(summary, dict):
        raise FormatError(f"{path}: not a JSON object")
    if not vessels:
        summary.pop("vessels", None)
    return summary


def _summary_head(path):
    """The members before "vessels" in hemosolve's layout; None for any other layout (or
    text that does not parse there)."""
    text = []
    with open(path) as f:
        for line in f:
            if line.rstrip("\n") == _VESSELS_LINE:
                try:
                    head = json.loads("".join(text) + '"vessels": []}')
                except json.JSONDecodeError:
                    return None
                if not isinstance(head, dict):
                    return None
                del head["vessels"]
                return head
            text.append(line)
    return None


# ---- CSV tables: vessels.csv and probes.csv ---------------------------------------------

def _read_header(f):
    """The header record of a CSV file open in binary mode, read line by line so that the
    file stays positioned at the first row (a quoted name may hold a line break); [] for an
    empty file."""
    text = f.readline()
    while text.count(b'"') % 2:  # inside a quoted name: the record goes on
        more = f.readline()
        if not more:
            break
        text += more
    return next(csv.reader(io.StringIO(text.decode("utf-8"), newline="")), [])


def _check_fields(path, start, count):
    """The number of rows after byte START; FormatError unless each holds COUNT fields
    (pandas would fill a short row with NaN, and drop a first row's extra fields). Each
    line's commas are counted with numpy, a block at a time (about 1 s for a 440 MB file);
    a file with quotes is read row by row instead."""
    import numpy as np
    rows = carry = 0  # carry: the commas of a line that an earlier block began
    last = b"\n"
    with open(path, "rb") as f:
        f.seek(start)
        while True:
            block = f.read(1 << 24)
            if not block:
                break
            if b'"' in block:
                return _find_bad_row(path, start, count)
            text = np.frombuffer(block, dtype=np.uint8)
            commas = np.flatnonzero(text == ord(","))
            ends = np.flatnonzero(text == ord("\n"))
            if len(ends):
                upto = np.searchsorted(commas, ends)  # commas before each line end
                per_line = np.diff(upto, prepend=0)
                per_line[0] += carry
                if np.any(per_line != count - 1):
                    return _find_bad_row(path, start, count)
                carry = len(commas) - int(upto[-1])
                rows += len(ends)
            else:
                carry += len(commas)
            last = block[-1:]
    if last != b"\n":  # a last row without its line end
        if carry != count - 1:
            return _find_bad_row(path, start, count)
        rows += 1
    return rows


def _find_bad_row(path, start, count):
    """The number of rows after byte START, read by the csv module; FormatError naming the
    first row that does not hold COUNT fields."""
    rows = 0
    with open(path, "rb") as f:
        f.seek(start)
        for row in csv.reader(io.TextIOWrapper(f, encoding="utf-8", newline="")):
            if len(row) != count:
                raise FormatError(f"{path}: a row of {len(row)} fields under {count} names")
            rows += 1
    return rows


def _read_table(path, text_columns=(), columns=None):
    """A CSV file of a header and rows of numbers (TEXT_COLUMNS: words) as a DataFrame with
    the header's names (duplicates kept), numbers as float64 or int64, words as categories;
    an empty file (no header) as an empty DataFrame.

    Read by pandas in chunks into columns allocated once: at its peak the memory of the
    table and one chunk (pandas' own whole-file read takes about four times the table)."""
    pd = _pandas()
    import numpy as np
    from pandas.api.types import union_categoricals
    with open(path, "rb") as f:
        names = _read_header(f)
        start = f.tell()
    if columns is not None:
        missing = [n for n in columns if n not in names]
        if missing:
            raise FormatError(f"{path}: no column {', '.join(missing)} (a hemosolve --out folder?)")
    if not names:
        return pd.DataFrame()
    rows = _check_fields(path, start, len(names))
    words = [k for k, n in enumerate(names) if n in text_columns]
    use = list(range(len(names))) if columns is None else [k for k, n in enumerate(names) if n in columns]
    numbers = {}  # position -> the column's values (int64 while every one is a whole number)
    labels = {k: [] for k in use if k in words}  # position -> its chunks' categoricals
    done = 0
    with open(path, "rb") as f:
        f.seek(start)
        chunks = pd.read_csv(f, header=None, names=range(len(names)), usecols=use,
                             dtype={k: "category" for k in words}, keep_default_na=False,
                             na_values={k: [""] for k in range(len(names)) if k not in words},
                             float_precision="round_trip", skip_blank_lines=False,
                             index_col=False, chunksize=1 << 16) if rows else []
        try:
            for chunk in chunks:
                n = len(chunk)
                for k in chunk.columns:
                    if k in labels:
                        labels[k].append(chunk[k].array)
                        continue
                    values = chunk[k].to_numpy()
                    if values.dtype.kind not in "if":  # texts pandas does not take for numbers
                        values = np.array([_number(x, path) for x in values], dtype=float)
                    column = numbers.get(k)
                    if column is None:
                        column = numbers[k] = np.empty(rows, dtype=values.dtype)
                    elif column.dtype.kind == "i" and values.dtype.kind != "i":
                        column = numbers[k] = column.astype(float)  # a null or a fraction
                    column[done:done + n] = values
                done += n
        except pd.errors.ParserError as e:
            raise FormatError(f"{path}: {' '.join(str(e).split())}") from None
    if done != rows:
        raise FormatError(f"{path}: {done} rows read of {rows}")
    data = {}
    for k in use:
        if k in labels:
            data[k] = union_categoricals(labels[k]) if labels[k] else pd.Categorical([])
        else:
            data[k] = numbers.get(k, np.empty(0))
    frame = pd.DataFrame(data, copy=False)
    frame.columns = [names[k] for k in use]
    frame.attrs["path"] = str(path)
    return frame


def _number(x, path):
    """float's verdict on a field pandas did not read as a number (NaN stays NaN; pandas
    reads True and False as booleans, which are not numbers either)."""
    if not isinstance(x, str):
        if isinstance(x, float):
            return x
        raise FormatError(f"{path}: {str(x)!r} is not a number")
    try:
        return float(x)
    except ValueError:
        raise FormatError(f"{path}: {x!r} is not a number") from None


def read_vessels(path, columns=None):
    """vessels.csv of a run (PATH: the run's folder or the file) as a DataFrame: one row per
    vessel, in summary.json's order, a column per field with the header's names; numbers as
    float64 (int64 for a whole-number column without nulls), NaN for an empty field (null);
    class and model as categories. COLUMNS (a list of names) reads those alone (less memory
    for a full tree); a name not in the header raises FormatError."""
    results = _results_h5(path)
    if results is not None:
        pd = _pandas()
        h5py = _h5py()
        with h5py.File(results, "r") as f:
            group = f["vessels"]
            names = list(group.keys()) if columns is None else columns
            missing = [n for n in names if n not in group]
            if missing:
                raise FormatError(f"{results}: no column {', '.join(missing)}")
            data = _h5_columns({n: group[n] for n in names})
        frame = pd.DataFrame(data, copy=False)
        frame.attrs["path"] = str(results)
        return frame
    return _read_table(_file(path, "vessels.csv"), TEXT_COLUMNS, columns)


def read_probes(path):
    """probes.csv of a run (PATH: the run's folder or the file, written with --probe) as a
    DataFrame: the time `t [s]` first, then per probe `p vessel ID x X [Pa]`, `Q ... [m^3/s]`,
    `A ... [m^2]`, `u ... [m/s]` and its tracers' `c_NAME vessel ID x X [unit]`, one row per
    sample (the header's names as they are: parse_probe_name takes them apart); an empty
    file as an empty DataFrame."""
    results = _results_h5(path)
    if results is not None:
        pd = _pandas()
        h5py = _h5py()
        with h5py.File(results, "r") as f:
            if "probes" not in f:
                return pd.DataFrame()
            frame = pd.DataFrame(f["probes/values"][:], columns=json.loads(_text(f["probes/columns"])))
        frame.attrs["path"] = str(results)
        return frame
    path = _file(path, "probes.csv")
    frame = _read_table(path)
    if len(frame.columns) and not frame.columns[0].strip().startswith("t"):
        raise FormatError(f"{path}: the first column must be the time `t [s]`, "
                          f"not {[frame.columns[0]]}")
    return frame


_PROBE_NAME = re.compile(r"^(.+?)\s+vessel\s+(-?\d+)\s+x\s+([-+0-9.eE]+)\s*(\[.*\])?$")


def parse_probe_name(name):
    """(quantity, vessel id, x, unit) of a probes.csv column name such as
    `p vessel 1 x 0.5 [Pa]` (unit "" where none is given); None for the time column."""
    m = _PROBE_NAME.match(name.strip())
    if not m:
        return None
    return m.group(1), int(m.group(2)), float(m.group(3)), m.group(4) or ""


def probe_column(probes, quantity, vessel, x):
    """The samples of QUANTITY (p, Q, A, u or c_NAME) at the probe on vessel VESSEL at X (within
    1e-6) as a numpy array; FormatError naming the probes there if there is no such column."""
    for j, name in enumerate(probes.columns):
        parsed = parse_probe_name(name)
        if parsed and parsed[0] == quantity and parsed[1] == vessel and abs(parsed[2] - x) < 1e-6:
            return probes.iloc[:, j].to_numpy(dtype=float)
    have = sorted({f"{p[1]}:{p[2]:g}" for p in map(parse_probe_name, probes.columns) if p})
    raise FormatError(f"{probes.attrs.get('path', 'probes.csv')}: no column `{quantity} vessel {vessel} "
                      f"x {x:g}` (probes there: {', '.join(have) or 'none'}; run hemosolve with "
                      f"--probe {vessel}:{x:g})")


# ---- other JSON outputs -----------------------------------------------------------------

def _load_json(source):
    if hasattr(source, "read"):
        return json.load(source)
    with open(source) as f:
        return json.load(f)


def _name(source):
    """A path as given; a stream by its name (sys.stdin: <stdin>)."""
    return getattr(source, "name", "the input") if hasattr(source, "read") else source


def read_network_stats(source):
    """The statistics of `vstats --json` (SOURCE: a file's path, or an open text stream such
    as sys.stdin) as a dict; FormatError unless it has "vessels" and a non-empty list of
    "generations", each with generation, vessels, classes and diameter."""
    stats = _load_json(source)
    gens = stats.get("generations") if isinstance(stats, dict) else None
    if (not isinstance(gens, list) or not gens or "vessels" not in stats
            or not all(isinstance(g, dict) and {"generation", "vessels", "classes", "diameter"}
                       <= set(g) for g in gens)):
        raise FormatError(f"{_name(source)}: not vstats --json output (no generations)")
    return stats


def read_profile_report(path):
    """The generation profile of `vprune --profile-report FILE` as a dict: lists "generation",
    "full", "target" and "achieved" (vessels per generation) and "total" (their sums)."""
    report = _load_json(path)
    lists = ("generation", "full", "target", "achieved")
    if (not isinstance(report, dict) or not all(isinstance(report.get(k), list) for k in lists)
            or not isinstance(report.get("total"), dict)):
        raise FormatError(f"{path}: not a vprune --profile-report (no generation, full, target, "
                          "achieved and total)")
    return report
