"""Turn raybench results and accuracy CSVs into a Markdown report with PNG plots.

    scripts/report RESULTS.csv [--out DIR] [--accuracy ACCURACY.csv ...] [--title TEXT]
                   [--max-error RATE]
    scripts/report --accuracy ACCURACY.csv [--accuracy ACCURACY.csv ...] [--out DIR] [--title TEXT]
                   [--max-error RATE]

Writes DIR/report.md (default DIR: <dir>/<stem>-report/ of RESULTS.csv, or of the first
--accuracy file when there is no RESULTS.csv) and, beside it, from RESULTS.csv:

- throughput-<rayset>[-t<threads>].png: median Mrays/s per scene and backend, min-max whiskers;
- ratio-<rayset>[-t<threads>].png: each non-Embree backend's ratio_to_embree per scene;
- pareto-<scene>[-t<threads>].png, only without --accuracy: speed versus 1 - agree_hit, which
  is disagreement with Embree, not error against a ground truth (on must-hit ray sets, which
  have a `leaks` count, leaks / rays, which is). Ray sets on which every backend sits at 0 are
  left out (all points on one vertical line); the report says, in one line, that no accuracy
  file was given and how to make one.

From each --accuracy file (results/accuracy.csv, results/accuracy-kernels.csv; the schema is
harness/src/accuracy/accuracy_csv.h; every row is one thread; error = false_miss + false_hit +
wrong_prim, fractions of rays, shown as %):

- pareto-<scene>.png: speed (mrays_s) versus error, every backend or kernel variant a point,
  the Pareto front joined, one panel per ray set. Ray sets that differ only in a parameter
  suffix (far-small-sphere:D=1e3) share a panel with their rays pooled (rays-weighted error,
  all rays / total time). Only the scene as given (scale 1, offset 0, or its only transform):
  rows of the stability sweep are left out;
- sweep-<scene>.png, for scenes traced at several scales and/or offsets: error rate against
  scale (log), one line per backend, one panel per ray set and offset (against the offset's
  distance when only the offset varies), with the numbers as tables and every row of the sweep;
- parameters-<scene>.png, for ray-set families with a numeric suffix: error rate against the
  parameter (e.g. D), one line per backend, with the numbers as tables;
- invalid-rays-<file stem>.png, for scenes with both invalid-rays and control-random ray sets:
  per backend, time per invalid ray / time per valid ray = mrays_s(control-random) /
  mrays_s(invalid-rays), with Embree's bar (2.5x) dashed, and a table saying whether each
  backend stays within it and answers every invalid ray as a miss (false_hit = 0);
- a table per scene (as given) with every row: rays, truth hits, error, false miss, false hit,
  wrong prim, ambiguous, self hits, ulp p50/p99/max, Mrays/s; the file's summary names the ray
  sets whose exact truth has no hit (they can only catch false hits);
- tessellation-<scene>.png, for scenes traced also as triangle stand-ins (representation
  uv<S>x<R>, scene <scene>@uv<S>x<R>; raybench run --tessellate): per ray set, speed against
  the error rate and against the t error (t_relerr_p99), each backend's analytic form a star and
  its stand-ins joined coarse to fine, with a table per ray set (triangles, build time and memory
  from RESULTS.csv when given). Stand-in rows stay out of every other plot and table;
- with --max-error RATE (a fraction of rays): per scene and ray set, the cheapest tessellation
  (fewest triangles) whose error stays within RATE for every backend that traced it, or that
  none does; and the advice: the fastest backend and representation (the scene as loaded or a
  stand-in) within RATE, or the most accurate one when none is.

The report starts with a "Run" section from the sidecar <csv without .csv>.meta.toml when
RESULTS.csv has one (an accuracy file's sidecar, if any, is summarised in its own section);
then the results' plots and one table per ray set; then one section per accuracy file. Empty
CSV fields mean "not applicable" and show "-".

Bad input (no input at all, a missing or empty file, missing schema columns, a field that is not
a number, two accuracy rows for the same scene, transform, ray set, query and backend, a stand-in
row whose scene does not end in @<its representation>, --max-error outside [0, 1] or without
--accuracy) prints one line `report: error: FILE: problem` on stderr, exits 2 and writes nothing.
"""
import argparse
import csv
import io
import math
import os
import re
import shutil
import sys
import tempfile
import textwrap
import tomllib

REFERENCE = "embree"

# The columns every plot and table needs; the rest of the raybench schema is optional here.
REQUIRED = ["scene", "rayset", "backend", "threads", "mrays_s", "mrays_s_min", "mrays_s_max",
            "ratio_to_embree", "hit_rate", "agree_hit", "agree_prim"]
NUMERIC = ["triangles", "rays", "threads", "build_ms", "build_ms_min", "build_ms_max",
           "memory_bytes", "mrays_s", "mrays_s_min", "mrays_s_max", "reps", "ratio_to_embree",
           "hit_rate", "agree_hit", "agree_prim", "prim_ties", "t_relerr_max", "t_relerr_p999",
           "disagreements", "leaks"]
# The accuracy CSV (harness/src/accuracy/accuracy_csv.h): every column is required, as raybench's
# own reader requires them. Rates are fractions of the row's rays; empty = not applicable.
ACCURACY_COLUMNS = ["scene", "scale", "offset_x", "offset_y", "offset_z", "rayset", "query",
                    "backend", "accuracy_class", "rays", "invalid", "truth_hits", "ambiguous",
                    "false_miss", "false_hit", "wrong_prim", "self_hits", "ulp_p50", "ulp_p99",
                    "ulp_max", "mrays_s", "mrays_s_min", "mrays_s_max"]
ACCURACY_NUMERIC = [c for c in ACCURACY_COLUMNS
                    if c not in ("scene", "rayset", "query", "backend", "accuracy_class")]
# Appended with issue 31; files written before it lack them (read as empty). representation:
# "triangles", "analytic" or "uv<S>x<R>", a triangle stand-in <scene>@uv<S>x<R> of <scene>.
ACCURACY_OPTIONAL_NUMERIC = ["t_relerr_p99", "t_relerr_max"]
STAND_IN = re.compile(r"^uv(?P<segments>[0-9]+)x(?P<rings>[0-9]+)$")
IDENTITY = (1.0, 0.0, 0.0, 0.0)  # (scale, offset_x, offset_y, offset_z): the scene as given
INVALID_RAYSET, CONTROL_RAYSET = "invalid-rays", "control-random"
INVALID_BAR = 2.5  # Embree's bar: an invalid ray costs at most 2.5x a valid one

DASH = "\u2013"  # en dash: the "not applicable" mark and the min-max separator
DPI = 110


class InputError(Exception):
    """Bad input: reported as one line `report: error: FILE: problem`, exit status 2."""

    def __init__(self, path, problem):
        super().__init__(f"{path}: {problem}")


# ---------------------------------------------------------------------------------------------
# Reading


def read_table(path, required, numeric, check=None):
    """Rows of a CSV as dicts, numeric fields as float (None when empty); InputError if bad.
    check(line, row), when given, validates one parsed row further (it knows the line)."""
    try:
        with open(path, newline="", encoding="utf-8-sig") as f:
            text = f.read()
    except FileNotFoundError:
        raise InputError(path, "no such file")
    except IsADirectoryError:
        raise InputError(path, "is a directory, not a CSV file")
    except UnicodeDecodeError:
        raise InputError(path, "not UTF-8 text")
    except OSError as e:
        raise InputError(path, e.strerror or str(e))
    if not text.strip():
        raise InputError(path, "empty file (no header, no rows)")
    reader = csv.DictReader(io.StringIO(text, newline=""))
    header = [name.strip() for name in reader.fieldnames or []]
    missing = [name for name in required if name not in header]
    if missing:
        raise InputError(path, "missing columns: " + ", ".join(missing))
    reader.fieldnames = header
    rows = []
    for row in reader:
        line = reader.line_num
        if None in row or None in row.values():
            raise InputError(path, f"line {line}: expected {len(header)} fields")
        parsed = parse_row(path, line, row, numeric)
        if check:
            check(line, parsed)
        rows.append(parsed)
    if not rows:
        raise InputError(path, "no data rows (header only)")
    return rows


def rate_samples(path, row):
    """A results row's rate samples in round order (mrays_s_samples, `;`-separated Mrays/s);
    InputError unless every one is a positive number."""
    text = row["mrays_s_samples"]
    try:
        samples = [float(s) for s in text.split(";")]
    except ValueError:
        samples = []
    if not samples or not all(s > 0 for s in samples):
        raise InputError(path, f"{row['scene']}/{row['rayset']}/{row['backend']}/threads {row['threads']}: "
                               f"mrays_s_samples must be positive numbers separated by ';', not {text!r}")
    return samples


def parse_row(path, line, row, numeric):
    """One CSV row with its numeric fields converted; threads become int."""
    parsed = {key: value.strip() for key, value in row.items()}
    for key in numeric:
        if key not in parsed:
            continue
        text = parsed[key]
        if text == "":
            parsed[key] = None
            continue
        try:
            parsed[key] = float(text)
        except ValueError:
            raise InputError(path, f"line {line}: column {key}: not a number: {text!r}")
    if "threads" in parsed:  # an accuracy file may have no threads column
        threads = parsed["threads"]
        if threads is None or not threads.is_integer():
            raise InputError(path, f"line {line}: column threads: not a whole number: "
                                   f"{row['threads']!r}")
        parsed["threads"] = int(threads)
    for key in ("scene", "rayset", "backend"):
        if not parsed.get(key):
            raise InputError(path, f"line {line}: column {key} is empty")
    return parsed


class AccuracyFile:
    """One --accuracy file: its path, its rows and its sidecar metadata ({} when absent).
    rows: the scenes traced as themselves; stand_ins: the rows of triangle stand-ins
    (representation uv<S>x<R>), kept apart for the tessellation study."""

    def __init__(self, path, rows, meta):
        self.path, self.meta = path, meta
        self.rows = [r for r in rows if r["stands_for"] is None]
        self.stand_ins = [r for r in rows if r["stands_for"] is not None]
        self.name = os.path.basename(path)
        self.stem = os.path.splitext(self.name)[0]


def read_accuracy(path):
    """An accuracy CSV. Beyond the schema: scale, offsets and rays must be given (rays a whole
    number), and no two rows may share scene, transform, ray set, query and backend, since
    every plot would silently pick one of them."""
    first_line = {}

    def check(line, row):
        for key in ("scale", "offset_x", "offset_y", "offset_z", "rays"):
            if row[key] is None:
                raise InputError(path, f"line {line}: column {key} is empty")
        if not row["rays"].is_integer() or row["rays"] < 0:
            raise InputError(path, f"line {line}: column rays: not a whole number: "
                                   f"{row['rays']!r}")
        row["rays"] = int(row["rays"])
        row["transform"] = (row["scale"], row["offset_x"], row["offset_y"], row["offset_z"])
        for key in ACCURACY_OPTIONAL_NUMERIC:
            row.setdefault(key, None)
        row["stands_for"] = stands_for(path, line, row)
        key = (row["scene"], row["transform"], row["rayset"], row["query"], row["backend"])
        if key in first_line:
            raise InputError(path, f"line {line}: same scene, scale, offset, rayset, query and "
                                   f"backend as line {first_line[key]}")
        first_line[key] = line

    rows = read_table(path, ACCURACY_COLUMNS, ACCURACY_NUMERIC + ACCURACY_OPTIONAL_NUMERIC, check)
    return AccuracyFile(path, rows, read_meta(path))


def stands_for(path, line, row):
    """The scene a stand-in row's triangles stand for (its name without @uv<S>x<R>), None for
    a scene traced as itself. Sets row["representation"] ("" in older files)."""
    representation = row.setdefault("representation", "")
    if representation in ("", "triangles", "analytic"):
        return None
    if not STAND_IN.match(representation):
        raise InputError(path, f"line {line}: column representation: expected triangles, "
                               f"analytic or uv<S>x<R>, got {representation!r}")
    suffix = "@" + representation
    if not row["scene"].endswith(suffix) or row["scene"] == suffix:
        raise InputError(path, f"line {line}: representation {representation} but scene "
                               f"{row['scene']!r} does not end in {suffix}")
    return row["scene"][:-len(suffix)]


def meta_path(csv_path):
    """The sidecar raybench writes beside a results CSV: <csv without .csv>.meta.toml."""
    stem, ext = os.path.splitext(csv_path)
    return (stem if ext.lower() == ".csv" else csv_path) + ".meta.toml"


def read_meta(csv_path):
    """The run's metadata as a dict, {} when the sidecar file does not exist."""
    path = meta_path(csv_path)
    if not os.path.exists(path):
        return {}
    try:
        with open(path, "rb") as f:
            return tomllib.load(f)
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as e:
        raise InputError(path, f"not valid TOML: {e}")
    except OSError as e:
        raise InputError(path, e.strerror or str(e))


# ---------------------------------------------------------------------------------------------
# Grouping and formatting


def ordered(values):
    """Distinct values in order of first appearance (the suite's order, not alphabetical)."""
    return list(dict.fromkeys(values))


def safe_name(text):
    """A file-name fragment: scene names may be mesh paths or proc:<name>."""
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text).strip("_.") or "x"


def thread_suffix(threads, all_threads):
    return f"-t{threads}" if len(all_threads) > 1 else ""


def thread_words(threads):
    return f"{threads} thread" + ("" if threads == 1 else "s")


def fmt_sig(value, digits=3):
    """A number to about `digits` significant digits, without exponent notation for big ones."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return DASH
    if abs(value) >= 10 ** digits:
        return f"{value:,.0f}"
    return f"{value:.{digits}g}"


def fmt_fraction(value, digits=6):
    """A fraction near 1 (agreement) that never rounds up to a misleading "1"."""
    if value is None:
        return DASH
    if value == 1:
        return "1"
    text = f"{value:.{digits}g}"
    while text in ("1", "100") and digits < 15:
        digits += 1
        text = f"{value:.{digits}g}"
    return text


def fmt_percent(value):
    if value is None:
        return DASH
    return fmt_fraction(value * 100, 4) + " %"


def fmt_rate(value):
    """A fraction of rays as a percentage: "0" only when exactly zero (one wrong ray in a
    million must not read as 0 %), three significant digits, never a rounded-up "100 %"."""
    if value is None or math.isnan(value):
        return DASH
    if value == 0:
        return "0"
    return fmt_fraction(value * 100, 3).replace("e-0", "e-") + " %"


def fmt_ulp(value):
    """ulp distances: small ones as they are, huge ones (a wrong t) in exponent form."""
    if value is None or math.isnan(value):
        return DASH
    return fmt_short(value) if abs(value) >= 1e5 else fmt_sig(value)


def fmt_short(value):
    """1e-06 -> 1e-6, 1000 -> 1e3, 148376 -> 148376: scales, offsets and ray-set parameters
    (round numbers from 1000 and up to 0.001 in exponent form, others in full up to 1e6)."""
    if value is None or math.isnan(value):
        return DASH
    if math.isinf(value):  # e.g. a t error where a kernel's t overflowed to infinity
        return "\u221e" if value > 0 else "\u2212\u221e"
    round_number = float(f"{value:.2g}") == value and not 1e-3 < abs(value) < 1e3
    if value != 0 and (abs(value) >= 1e6 or abs(value) < 1e-3 or round_number):
        mantissa, exponent = f"{value:.2e}".split("e")
        return f"{mantissa.rstrip('0').rstrip('.')}e{int(exponent)}"
    return f"{value:.6g}"


def fmt_offset(transform):
    _, *offset = transform
    return "0" if not any(offset) else "(" + ", ".join(fmt_short(v) for v in offset) + ")"


def offset_text(row):
    return fmt_offset(row["transform"])


def fmt_transform(transform):
    """"scale 1e3, offset (148376, 1234, -223423)" -- "as given" for the identity."""
    if transform == IDENTITY:
        return "as given"
    return f"scale {fmt_short(transform[0])}, offset {fmt_offset(transform)}"


def fmt_throughput(row):
    median = fmt_sig(row["mrays_s"])
    if row["mrays_s_min"] is None or row["mrays_s_max"] is None:
        return median
    return f"{median} [{fmt_sig(row['mrays_s_min'])}{DASH}{fmt_sig(row['mrays_s_max'])}]"


def fmt_mib(value):
    return DASH if value is None else fmt_sig(value / 2 ** 20)


def fmt_count(value):
    """Triangle counts as 262k / 1.0M: short enough for an axis label."""
    if value is None:
        return ""
    if value >= 1e6:
        return f"{value / 1e6:.1f}M"
    if value >= 1e3:
        return f"{value / 1e3:.0f}k"
    return f"{value:.0f}"


def md_escape(text):
    return str(text).replace("|", "\\|")


def backend_colors(backends):
    """One colour per backend, the same in every figure."""
    from matplotlib import colormaps
    palette = colormaps["tab10" if len(backends) <= 10 else "tab20"].colors
    return {name: palette[i % len(palette)] for i, name in enumerate(backends)}


# ---------------------------------------------------------------------------------------------
# Plots. Each returns nothing and saves one PNG; matplotlib is imported only once the input
# has been validated, so bad input fails fast.


def pyplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    plt.rcParams.update({"font.size": 9, "axes.titlesize": 10, "figure.titlesize": 11,
                         "axes.spines.top": False, "axes.spines.right": False})
    return plt


def log_axis(ax):
    """A log y axis labelled 0.5, 1, 2, 5, 10, ... rather than only at powers of ten."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter
    ax.set_yscale("log", nonpositive="clip")
    ax.yaxis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    ax.yaxis.set_minor_formatter(NullFormatter())


def wide_range(values, factor=8.0):
    """True when positive values span more than `factor`: then a log axis reads better."""
    positive = [v for v in values if v is not None and v > 0]
    return len(positive) > 1 and max(positive) / min(positive) > factor


def label_width(groups):
    """Inches a group needs for its scene label: about 0.07 in per 9-pt character."""
    return max(1.15, 0.07 * max((len(g) for g in groups), default=0) + 0.2)


def figure_width(groups, n_series):
    """Wide enough for the bars, each group's label and the legend (2.5 in); past 24 in,
    labels rotate instead (rotate_if_crowded)."""
    per_group = max(label_width(groups), 0.28 * n_series + 0.35)
    return min(24.0, max(7.0, 2.5 + len(groups) * per_group))


def scene_labels(scenes, triangles):
    return [f"{s}\n{fmt_count(triangles.get(s))} tris" if triangles.get(s) else s for s in scenes]


def draw_grouped_bars(ax, scenes, series, colors, value_of, whiskers=True):
    """Bars grouped by scene, one per series; value_of(scene, series) -> (median, lo, hi)."""
    n = max(len(series), 1)
    width = 0.8 / n
    for i, name in enumerate(series):
        xs, heights, lows, highs = [], [], [], []
        for g, scene in enumerate(scenes):
            value = value_of(scene, name)
            if value is None or value[0] is None:
                continue
            median, lo, hi = value
            xs.append(g - 0.4 + width * (i + 0.5))
            heights.append(median)
            lows.append(median - lo if lo is not None else 0.0)
            highs.append(hi - median if hi is not None else 0.0)
        ax.bar(xs, heights, width * 0.92, label=name, color=colors[name], zorder=2)
        if whiskers and xs:
            ax.errorbar(xs, heights, yerr=[lows, highs], fmt="none", ecolor="black",
                        elinewidth=1.0, capsize=max(1.5, 6 / n), capthick=1.0, zorder=3)
    ax.set_xticks(range(len(scenes)))
    ax.set_xlim(-0.6, len(scenes) - 0.4)
    ax.grid(axis="y", which="major", alpha=0.35, zorder=0)


def rotate_if_crowded(ax, fig, groups):
    """Rotate scene labels when the figure, at its widest, still gives a group less room
    than its label needs (some 20 scenes)."""
    if (fig.get_figwidth() - 2.5) / max(len(groups), 1) < 0.95 * label_width(groups):
        for label in ax.get_xticklabels():
            label.set_rotation(30)
            label.set_ha("right")
            label.set_rotation_mode("anchor")


def plot_throughput(path, rows, scenes, backends, colors, title, triangles):
    plt = pyplot()
    by_key = {(r["scene"], r["backend"]): r for r in rows}

    def value_of(scene, backend):
        row = by_key.get((scene, backend))
        return None if row is None else (row["mrays_s"], row["mrays_s_min"], row["mrays_s_max"])

    fig, ax = plt.subplots(figsize=(figure_width(scenes, len(backends)), 4.8),
                           layout="constrained")
    draw_grouped_bars(ax, scenes, backends, colors, value_of)
    values = [r[k] for r in rows for k in ("mrays_s", "mrays_s_min", "mrays_s_max")]
    if wide_range(values):
        log_axis(ax)
        ax.set_ylabel("throughput (Mrays/s, log scale)")
    else:
        ax.set_ylabel("throughput (Mrays/s)")
    ax.set_xticklabels(scene_labels(scenes, triangles))
    rotate_if_crowded(ax, fig, scenes)
    ax.set_title(wrap_title(title, fig))
    ax.legend(title="backend (median, whisker: min\u2013max)", loc="upper left",
              bbox_to_anchor=(1.0, 1.0), frameon=False)
    fig.savefig(path, dpi=DPI)
    plt.close(fig)


def wrap_title(text, fig):
    """Titles wrapped to the figure: a one-scene figure is narrower than its title."""
    width = max(30, int(fig.get_figwidth() * 10))
    return "\n".join(textwrap.fill(line, width) for line in text.splitlines())


def geometric_mean(values):
    positive = [v for v in values if v is not None and v > 0]
    return math.exp(sum(map(math.log, positive)) / len(positive)) if positive else None


def plot_ratio(path, rows, scenes, backends, colors, title, triangles):
    plt = pyplot()
    by_key = {(r["scene"], r["backend"]): r["ratio_to_embree"] for r in rows}
    # A last group with each backend's geometric mean over scenes: the one-number summary.
    summary = ["geo. mean"] if len(scenes) > 1 else []
    groups = scenes + summary
    means = {b: geometric_mean([by_key.get((s, b)) for s in scenes]) for b in backends}

    def value_of(scene, backend):
        ratio = means[backend] if scene == "geo. mean" else by_key.get((scene, backend))
        return None if ratio is None else (ratio, None, None)

    fig, ax = plt.subplots(figsize=(figure_width(groups, len(backends)), 4.8),
                           layout="constrained")
    draw_grouped_bars(ax, groups, backends, colors, value_of, whiskers=False)
    ax.axhline(1.0, color="black", linewidth=1.2, linestyle="--", zorder=4,
               label="Embree (= 1.0)")
    if summary:
        ax.axvline(len(scenes) - 0.5, color="grey", linewidth=0.8, zorder=1)
    ratios = [v for v in by_key.values() if v is not None] + [1.0]
    if wide_range(ratios, 20):
        log_axis(ax)
        ax.set_ylabel("throughput / Embree's (log scale)")
    else:
        ax.set_ylim(0, max(ratios) * 1.12)
        ax.set_ylabel("throughput / Embree's (\u00d7)")
    if len(backends) <= 3:
        label_bars(ax)
    ax.set_xticklabels(scene_labels(scenes, triangles) + summary)
    rotate_if_crowded(ax, fig, groups)
    ax.set_title(wrap_title(title, fig))
    ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), frameon=False)
    fig.savefig(path, dpi=DPI)
    plt.close(fig)


def label_bars(ax):
    """Write each bar's value above it: readable when there are few bars per scene."""
    for container in ax.containers:
        if hasattr(container, "patches") and container.patches:
            ax.bar_label(container, fmt="%.2f", fontsize=7, padding=1.5)


def pareto_front(points):
    """The points no other point beats on both speed (higher) and error (lower), by error."""
    front = []
    for p in points:
        dominated = any(q["speed"] >= p["speed"] and q["error"] <= p["error"]
                        and (q["speed"] > p["speed"] or q["error"] < p["error"]) for q in points)
        if not dominated:
            front.append(p)
    return sorted(front, key=lambda p: (p["error"], -p["speed"]))


def symlog_threshold(errors, rays):
    """Below this the x axis is linear: one ray's error, or the smallest error seen."""
    candidates = [e for e in errors if e > 0] + ([1.0 / rays] if rays else [1e-6])
    return 10.0 ** math.floor(math.log10(min(candidates)))


def plot_pareto(path, panels, colors, title, notes):
    """panels: [(rayset, [point]), ...]; point: dict(backend, error, speed, rays)."""
    save(pareto_figure(panels, colors, title, notes), path)


def save(fig, path):
    fig.savefig(path, dpi=DPI)
    pyplot().close(fig)


def pareto_figure(panels, colors, title, notes):
    plt = pyplot()
    ncols = min(len(panels), 4)
    nrows = math.ceil(len(panels) / ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(4.1 * ncols + 0.4, 3.7 * nrows + 0.7),
                             layout="constrained", squeeze=False)
    for ax in axes.flat[len(panels):]:
        ax.set_visible(False)
    for ax, (rayset, points) in zip(axes.flat, panels):
        draw_pareto_panel(ax, rayset, points, colors)
    legend = ("filled: the Pareto front (dashed line), no other backend both faster and more "
              "accurate; hollow: dominated")
    fig.suptitle(wrap_title("\n".join([title, *notes, legend]), fig))
    return fig


def draw_pareto_panel(ax, rayset, points, colors):
    errors = [p["error"] for p in points]
    rays = max((p["rays"] or 0 for p in points), default=0)
    front = pareto_front(points)
    ax.plot([p["error"] for p in front], [p["speed"] for p in front], color="grey",
            linestyle="--", linewidth=1.2, zorder=1, label="Pareto front")
    on_front = {id(p) for p in front}
    for p in points:
        filled = id(p) in on_front
        ax.scatter([p["error"]], [p["speed"]], s=42, zorder=3, linewidths=1.5,
                   color=colors[p["backend"]] if filled else "white",
                   edgecolors=colors[p["backend"]])
    error_axis(ax, "x", errors, rays, percent=points[0]["kind"] == "accuracy")
    speeds = [p["speed"] for p in points]
    if wide_range(speeds, 10):
        log_axis(ax)
        ax.set_ylim(min(speeds) / 1.5, max(speeds) * 1.5)  # room for the labels
    else:
        ax.set_ylim(0, max(speeds) * 1.2)
    annotate_points(ax, points)
    ax.set_title(rayset)
    ax.set_xlabel(ERROR_KINDS[points[0]["kind"]][0])
    ax.set_ylabel("throughput (Mrays/s)")
    ax.grid(alpha=0.3, zorder=0)


def annotate_points(ax, points):
    """Backend names beside their points, nudged apart vertically where labels would overlap.

    Works in axes fractions (data -> [0, 1]) with estimated label widths rather than measured
    pixels: a full canvas draw per panel to measure them would triple the rendering time."""
    ax.autoscale_view()
    to_axes = (ax.transScale + ax.transLimits).transform
    height_pt = ax.figure.get_figheight() * 72 * ax.get_position().height
    width_pt = ax.figure.get_figwidth() * 72 * ax.get_position().width
    min_gap = 10.0 / height_pt  # one line of 8-pt text
    placed = []  # (x0, x1, y) of labels already placed, in axes fractions
    for p in sorted(points, key=lambda p: -p["speed"]):
        x, y = to_axes((p["error"], p["speed"]))
        pad, width = 5.0 / width_pt, (5.0 * len(p["backend"]) + 2) / width_pt
        left = x + pad + width > 1.0  # would leave the axes: put it left of the point
        x0, x1 = (x - pad - width, x - pad) if left else (x + pad, x + pad + width)
        label_y, moved = y, True
        while moved:  # each move goes strictly down (0.99: rounding), so this ends
            moved = False
            for px0, px1, py in placed:
                if x0 < px1 and px0 < x1 and abs(py - label_y) < 0.99 * min_gap:
                    label_y, moved = py - min_gap, True
        placed.append((x0, x1, label_y))
        ax.annotate(p["backend"], (p["error"], p["speed"]),
                    xytext=(-5 if left else 5, 2 + (label_y - y) * height_pt),
                    textcoords="offset points", fontsize=8, va="bottom",
                    ha="right" if left else "left",
                    arrowprops=None if label_y == y else {"arrowstyle": "-", "color": "0.6",
                                                          "linewidth": 0.6})


# ---------------------------------------------------------------------------------------------
# Accuracy rows: what belongs together


def error_rate(row):
    """false_miss + false_hit + wrong_prim, the fraction of rays answered wrongly; the parts
    that do not apply (empty) count 0, and a row where none applies has no error rate."""
    parts = [row[k] for k in ("false_miss", "false_hit", "wrong_prim") if row[k] is not None]
    return sum(parts) if parts else None


PARAMETER = re.compile(r"^(?P<family>.+):(?P<name>[A-Za-z_][A-Za-z0-9_]*)=(?P<value>[^:=]+)$")


def rayset_parameter(rayset):
    """("far-small-sphere", "D", 1000.0) for "far-small-sphere:D=1e3": ray sets that differ
    only in such a suffix are one family, plotted against the parameter; (rayset, None, None)
    when there is no numeric suffix."""
    match = PARAMETER.match(rayset)
    if match:
        try:
            return match["family"], match["name"], float(match["value"])
        except ValueError:
            pass
    return rayset, None, None


def parameter_texts(rows):
    """Parameter value -> its text as written in the ray-set names ("1e2", not "100")."""
    return {rayset_parameter(r["rayset"])[2]: r["rayset"].rsplit("=", 1)[1] for r in rows
            if rayset_parameter(r["rayset"])[1]}


def rayset_label(rayset, query):
    """A ray set (or family) as a panel title: occlusion queries marked, closest hit implied."""
    return rayset + (" (any hit)" if query == "occluded" else "")


def family_label(row):
    return rayset_label(rayset_parameter(row["rayset"])[0], row["query"])


def pooled(rows, value_of):
    """A rate over several rows on disjoint rays: the rays-weighted mean (None if any is
    missing). One row: its own value, even when it has no rays."""
    values = [value_of(r) for r in rows]
    if any(v is None for v in values):
        return None
    if len(rows) == 1:
        return values[0]
    rays = sum(r["rays"] for r in rows)
    return sum(v * r["rays"] for v, r in zip(values, rows)) / rays if rays else None


def pooled_speed(rows):
    """Mrays/s over several rows: all rays / total time (None unless every row was timed)."""
    if len(rows) == 1:
        return rows[0]["mrays_s"]
    if any(not r["mrays_s"] or r["mrays_s"] <= 0 for r in rows):
        return None
    rays = sum(r["rays"] for r in rows)
    return rays / sum(r["rays"] / r["mrays_s"] for r in rows) if rays else None


def pooled_words(family):
    """", D=1e2..1e10 pooled" for a family of parametrised ray sets; "" for a single ray set."""
    values = sorted({rayset_parameter(r["rayset"])[2] for r in family} - {None})
    if len(ordered(r["rayset"] for r in family)) < 2 or not values:
        return ""
    name, texts = rayset_parameter(family[0]["rayset"])[1], parameter_texts(family)
    return f", {name}={texts[values[0]]}..{texts[values[-1]]} pooled"


def scene_family(name):
    """The scene a sweep copy was made from: raybench names the copies of a manifest `sweep`
    <name>@s<scale>[@o<x>_<y>_<z>] (meshes/accuracy.toml), so they group under <name>."""
    return name.split("@", 1)[0]


def by_scene_transform(rows):
    """scene family -> {transform -> rows}, in file order. A sweep copy at scale 1, offset 0
    repeats rows of the scene as given (same rays, same answers): the first row is kept."""
    scenes, seen = {}, set()
    for r in rows:
        family = scene_family(r["scene"])
        key = (family, r["transform"], r["rayset"], r["query"], r["backend"])
        if key in seen:
            continue
        seen.add(key)
        scenes.setdefault(family, {}).setdefault(r["transform"], []).append(r)
    return scenes


def base_transform(transforms):
    """The transform a scene's Pareto plot and main table show: the scene as given (scale 1,
    offset 0), or its only transform; None for a sweep without the untransformed scene."""
    if IDENTITY in transforms:
        return IDENTITY
    return next(iter(transforms)) if len(transforms) == 1 else None


def group_by(rows, key):
    """key(row) -> rows, in order of first appearance."""
    groups = {}
    for r in rows:
        groups.setdefault(key(r), []).append(r)
    return groups


# ---------------------------------------------------------------------------------------------
# Accuracy plots


def percent_formatter():
    from matplotlib.ticker import FuncFormatter
    return FuncFormatter(
        lambda v, _: "0" if v == 0 else re.sub(r"e([+-])0*(\d)", r"e\1\2", f"{v * 100:.6g}")
        .replace("e+", "e") + " %")


# Labelled ticks an axis of a panel holds without overlap: x labels such as "0.0001 %" are
# about 0.6 in wide on a 3.5 in axis; y labels only need a line of height each.
MAX_X_LABELS, MAX_Y_LABELS = 5, 8


def symlog_ticks(axis, linthresh, top, max_labels):
    """Ticks of a symlog axis (linear scale 1: 0 to linthresh is one decade wide): 0, then
    powers of ten from linthresh up, every `stride`-th labelled so that at most max_labels
    labels show, the others minor ticks. matplotlib's own locator also puts labelled ticks at
    the powers of ten inside the linear region, squeezed against 0, where they overlap.
    With a stride of k the first labelled decade is k decades above 0, as every other gap."""
    from matplotlib.ticker import FixedLocator, NullFormatter
    first = math.ceil(math.log10(linthresh) - 1e-9)
    last = math.floor(math.log10(top) + 1e-9) if top > 0 else first
    decades = list(range(first, max(first, last) + 1))
    stride = max(1, math.ceil(len(decades) / max(max_labels - 1, 1)))
    labelled = decades[stride - 1::stride]
    axis.set_major_locator(FixedLocator([0.0] + [10.0 ** d for d in labelled]))
    axis.set_minor_locator(FixedLocator([10.0 ** d for d in decades if d not in labelled]))
    axis.set_minor_formatter(NullFormatter())


def error_axis(ax, which, errors, rays, percent):
    """A symlog error axis: linear below one ray's worth, where the many exact zeros sit,
    logarithmic above, so 0.001 % and 10 % are both readable."""
    threshold = symlog_threshold(errors, rays)
    top = min(max(max(errors, default=0.0) * 4, threshold * 100), 2.0 if percent else math.inf)
    axis = ax.xaxis if which == "x" else ax.yaxis
    if which == "x":
        ax.set_xscale("symlog", linthresh=threshold, linscale=1.0)
        ax.set_xlim(-0.6 * threshold, top)
    else:
        ax.set_yscale("symlog", linthresh=threshold, linscale=1.0)
        ax.set_ylim(-0.6 * threshold, top)
    symlog_ticks(axis, threshold, top, MAX_X_LABELS if which == "x" else MAX_Y_LABELS)
    if percent:
        axis.set_major_formatter(percent_formatter())


def number_axis(ax, values):
    """The x axis of an error-against-a-number plot: log when every value is positive and
    they span decades (scales 1e-6..1e6, distances 1e2..1e10), symlog when 0 is among them
    (an offset of 0), linear otherwise."""
    from matplotlib.ticker import FuncFormatter
    positive = [v for v in values if v > 0]
    if positive and len(positive) == len(values) and wide_range(values, 8):
        ax.set_xscale("log")
    elif positive and any(v == 0 for v in values) and wide_range(positive, 8):
        ax.set_xscale("symlog", linthresh=min(positive), linscale=1.0)
        symlog_ticks(ax.xaxis, min(positive), max(positive), MAX_X_LABELS)
    ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: fmt_short(v)))


MARKERS = "osD^vP<>X*h"


def plot_error_lines(path, panels, ncols, colors, title):
    """Error rate against a number, one line per backend: how each kernel degrades as the
    scene is scaled or moved away from the origin, or as a ray-set parameter grows.
    panels: [(panel title, x label, {backend: [(x, error, rays)]})]. Backends at the same
    error overlap, so each has its own marker as well as its colour."""
    save(error_lines_figure(panels, ncols, colors, title), path)


def error_lines_figure(panels, ncols, colors, title):
    plt = pyplot()
    from matplotlib.lines import Line2D
    nrows = math.ceil(len(panels) / ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(4.2 * ncols + 2.2, 3.3 * nrows + 0.9),
                             layout="constrained", squeeze=False)
    for ax in axes.flat[len(panels):]:
        ax.set_visible(False)
    backends = ordered(b for _, _, series in panels for b in series)
    marker = {b: MARKERS[i % len(MARKERS)] for i, b in enumerate(backends)}
    for ax, (name, x_label, series) in zip(axes.flat, panels):
        xs_all, errors, rays = [], [], 0
        for backend, points in series.items():
            points = sorted(points)
            xs, ys = [p[0] for p in points], [p[1] for p in points]
            ax.plot(xs, ys, marker=marker[backend], markersize=4.5, linewidth=1.2, alpha=0.85,
                    color=colors[backend], markerfacecolor="none", markeredgewidth=1.2)
            xs_all += xs
            errors += ys
            rays = max([rays] + [p[2] or 0 for p in points])
        number_axis(ax, xs_all)
        error_axis(ax, "y", errors, rays, percent=True)
        ax.set_title(name)
        ax.set_xlabel(x_label)
        ax.set_ylabel("error rate (% of rays, symlog)")
        ax.grid(alpha=0.3)
    # Lines at the same error hide each other: the legend says how high each one gets.
    worst = {b: max(p[1] for _, _, series in panels for p in series.get(b, [])) for b in backends}
    handles = [Line2D([], [], color=colors[b], marker=marker[b], markerfacecolor="none",
                      label=f"{b} (max {fmt_rate(worst[b])})") for b in backends]
    axes.flat[min(ncols, len(panels)) - 1].legend(handles=handles, title="backend (max error)",
                                                   loc="upper left", bbox_to_anchor=(1.02, 1.0),
                                                   frameon=False)
    fig.suptitle(wrap_title(title, fig))
    return fig


def plot_invalid_rays(path, costs, colors, title):
    """Bars of the cost of an invalid ray relative to a valid one, grouped by scene, with
    Embree's bar (2.5x) dashed: NaN/Inf screening must be cheap, and must not turn into a
    full traversal. Hatched bars: the backend answered a hit for some invalid ray."""
    plt = pyplot()
    from matplotlib.patches import Patch
    groups = ordered(c["group"] for c in costs)
    backends = ordered(c["backend"] for c in costs)
    by_key = {(c["group"], c["backend"]): c for c in costs}

    def value_of(group, backend):
        cost = by_key.get((group, backend))
        return None if cost is None else (cost["slowdown"], None, None)

    fig, ax = plt.subplots(figsize=(figure_width(groups, len(backends)), 4.8),
                           layout="constrained")
    draw_grouped_bars(ax, groups, backends, colors, value_of, whiskers=False)
    bars = [c for c in ax.containers if hasattr(c, "patches")]
    for backend, container in zip(backends, bars):
        present = [g for g in groups if (g, backend) in by_key]
        for group, patch in zip(present, container.patches):
            if by_key[(group, backend)]["false_hit"]:
                patch.set_hatch("////")
                patch.set_edgecolor("black")
    ax.axhline(INVALID_BAR, color="black", linewidth=1.2, linestyle="--", zorder=4,
               label=f"Embree's bar: {INVALID_BAR:g}\u00d7 a valid ray")
    values = [c["slowdown"] for c in costs] + [INVALID_BAR]
    if wide_range(values, 20):
        log_axis(ax)
        ax.set_ylabel("time per invalid ray / per valid ray (log scale)")
    else:
        ax.set_ylim(0, max(values) * 1.15)
        ax.set_ylabel("time per invalid ray / per valid ray (\u00d7)")
    if len(backends) <= 4:
        label_bars(ax)
    ax.set_xticklabels(groups)
    rotate_if_crowded(ax, fig, groups)
    ax.set_title(wrap_title(title, fig))
    handles, _ = ax.get_legend_handles_labels()
    if any(c["false_hit"] for c in costs):
        handles.append(Patch(facecolor="white", edgecolor="black", hatch="////",
                             label="hit an invalid ray"))
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.0, 1.0), frameon=False)
    fig.savefig(path, dpi=DPI)
    plt.close(fig)


# ---------------------------------------------------------------------------------------------
# What to plot


class Plot:
    """One PNG: where it goes in the report and how to draw it."""

    def __init__(self, section, heading, sentence, filename, draw, extra=()):
        self.section, self.heading, self.sentence = section, heading, sentence
        self.filename, self.draw = filename, draw
        self.extra = list(extra)  # Markdown lines after the image (a table of its numbers)


def rayset_caption(rows, rayset):
    query = next((r.get("query") for r in rows if r["rayset"] == rayset and r.get("query")), "")
    return f"{rayset} rays" + (f" ({'any hit' if query == 'occluded' else 'closest hit'})"
                               if query else "")


def rays_words(rows):
    counts = ordered(int(r["rays"]) for r in rows if r.get("rays"))
    return f"{counts[0]:,} rays per scene; " if len(counts) == 1 else ""


def throughput_plots(rows, scenes, backends, raysets, all_threads, colors, triangles):
    plots = []
    for rayset in raysets:
        for threads in all_threads:
            subset = [r for r in rows if r["rayset"] == rayset and r["threads"] == threads]
            if not subset:
                continue
            present = [b for b in backends if any(r["backend"] == b for r in subset)]
            in_plot = [sc for sc in scenes if any(r["scene"] == sc for r in subset)]
            reps = ordered(int(r["reps"]) for r in subset if r.get("reps"))
            reps_text = f"{reps[0]} repetitions" if len(reps) == 1 else "repetitions"
            title = (f"Throughput, {rayset_caption(rows, rayset)}, {thread_words(threads)}\n"
                     f"{rays_words(subset)}higher is better")
            filename = f"throughput-{safe_name(rayset)}{thread_suffix(threads, all_threads)}.png"
            plots.append(Plot(
                "Throughput", f"{rayset_caption(rows, rayset)}, {thread_words(threads)}",
                f"One group per scene, one bar per backend: the median Mrays/s over {reps_text}, "
                "whiskers from the slowest to the fastest repetition; higher is faster.",
                filename,
                lambda path, s=subset, sc=in_plot, p=present, t=title: plot_throughput(
                    path, s, sc, p, colors, t, triangles)))
    return plots


def ratio_plots(rows, scenes, backends, raysets, all_threads, colors, triangles):
    plots = []
    others = [b for b in backends if b != REFERENCE]
    for rayset in raysets:
        for threads in all_threads:
            subset = [r for r in rows if r["rayset"] == rayset and r["threads"] == threads
                      and r["backend"] != REFERENCE and r["ratio_to_embree"] is not None]
            if not subset:
                continue
            present = [b for b in others if any(r["backend"] == b for r in subset)]
            in_plot = [sc for sc in scenes if any(r["scene"] == sc for r in subset)]
            mean = " (the last group is the geometric mean over scenes)" if len(in_plot) > 1 else ""
            title = (f"Ratio to Embree, {rayset_caption(rows, rayset)}, {thread_words(threads)}\n"
                     "measured within one run: same rays, interleaved repetitions")
            filename = f"ratio-{safe_name(rayset)}{thread_suffix(threads, all_threads)}.png"
            plots.append(Plot(
                "Ratio to Embree", f"{rayset_caption(rows, rayset)}, {thread_words(threads)}",
                f"Each bar is a backend's median throughput divided by Embree's in the same run"
                f"{mean}; above the dashed line at 1.0 is faster than Embree, below is slower.",
                filename,
                lambda path, s=subset, sc=in_plot, p=present, t=title: plot_ratio(
                    path, s, sc, p, colors, t, triangles)))
    return plots


# What a point's error means, by where it came from: the x-axis label and the figure's note.
ERROR_KINDS = {
    "accuracy": ("error rate (% of rays, symlog)",
                 "error = false miss + false hit + wrong triangle, % of rays "
                 "(from the accuracy file, judged by the exact referee)"),
    "disagree": ("1 \u2212 agree_hit: disagreement with Embree (symlog)",
                 "error = 1 \u2212 agree_hit: hit/miss DISAGREEMENT WITH EMBREE "
                 "(not ground truth; Embree is 0 by definition)"),
    "leaks": ("leaked rays / rays (every ray must hit; symlog)",
              "must-hit ray sets: error = leaks / rays, ground truth (every ray must hit)"),
}


def error_points_from_results(rows):
    """The fallback without an accuracy file: 1 - agree_hit (hit/miss disagreement with
    Embree), except on must-hit ray sets, where `leaks` / rays is a true error rate and
    Embree itself leaks, so disagreement with it would mislead."""
    groups = {}
    for r in rows:
        if r["mrays_s"] is None:
            continue
        if r.get("leaks") is not None and r.get("rays"):
            error, kind = r["leaks"] / r["rays"], "leaks"
        elif r["agree_hit"] is not None:
            error, kind = max(0.0, 1.0 - r["agree_hit"]), "disagree"
        else:
            continue
        point = {"backend": r["backend"], "error": error, "speed": r["mrays_s"],
                 "rays": r.get("rays"), "kind": kind}
        groups.setdefault((r["scene"], r["rayset"], r["threads"]), []).append(point)
    return groups


def pareto_sentence(kinds):
    if kinds == {"leaks"}:
        error = "more rays leaked through a closed mesh"
    else:
        error = ("more rays on which it disagrees with Embree about hit or miss (not an error "
                 "against ground truth: Embree itself sits at 0 by definition)")
        if "leaks" in kinds:
            error += "; on must-hit ray sets, more rays leaked (ground truth)"
    return (f"Each point is a backend, further right = {error}, higher = faster; the dashed "
            "line joins the Pareto front (backends no other backend beats on both speed and "
            "error), drawn as filled points.")


def pareto_plots(groups, raysets, colors, triangles, used):
    """Speed versus error from a results file alone (no --accuracy): see
    error_points_from_results for what the error is."""
    scenes = ordered(key[0] for key in groups)
    raysets = [rs for rs in raysets if any(k[1] == rs for k in groups)] + \
        ordered(k[1] for k in groups if k[1] not in raysets)
    all_threads = sorted(ordered(k[2] for k in groups), key=lambda t: (t is None, t or 0))
    plots = []
    for scene in scenes:
        for threads in all_threads:
            # A panel where every backend sits at error 0 says nothing the throughput plot
            # does not: left out, and named in the sentence.
            present = [rs for rs in raysets if (scene, rs, threads) in groups]
            panels = [(rs, groups[(scene, rs, threads)]) for rs in present
                      if any(p["error"] > 0 for p in groups[(scene, rs, threads)])]
            if not panels:
                continue
            left_out = [rs for rs in present if rs not in dict(panels)]
            kinds = {p["kind"] for _, points in panels for p in points}
            suffix = f"-t{threads}" if len(all_threads) > 1 and threads is not None else ""
            filename = unique_name(f"pareto-{safe_name(scene)}{suffix}", used)
            tris = triangles.get(scene)
            heading = scene + (f", {thread_words(threads)}" if suffix else "")
            title = (f"Speed versus error: {scene}" + (f" ({tris:,.0f} triangles)" if tris else "")
                     + (f", {thread_words(threads)}" if suffix else ""))
            notes = [ERROR_KINDS[k][1] for k in ERROR_KINDS if k in kinds]
            sentence = pareto_sentence(kinds) + (
                " Not plotted, every backend at 0: " + ", ".join(left_out) + "." if left_out else "")
            plots.append(Plot("Speed versus error", heading, sentence, filename,
                              lambda path, p=panels, t=title, n=notes: plot_pareto(
                                  path, p, colors, t, n)))
    return plots


def unique_name(stem, used):
    """stem.png, or stem-2.png when two scene names sanitise to the same file name."""
    name, n = f"{stem}.png", 1
    while name in used:
        n += 1
        name = f"{stem}-{n}.png"
    used.add(name)
    return name


# ---------------------------------------------------------------------------------------------
# One accuracy file: what to plot, and its part of the report


ACCURACY_HEADER = ["ray set", "backend", "class", "rays", "truth hits", "error", "false miss", "false hit",
                   "wrong prim", "ambiguous", "self hits", "ulp p50", "ulp p99", "ulp max",
                   "Mrays/s"]


def accuracy_cells(row):
    return [md_escape(rayset_label(row["rayset"], row["query"])), md_escape(row["backend"]),
            md_escape(row["accuracy_class"]) or DASH, f"{row['rays']:,}",
            fmt_rate(row["truth_hits"]), fmt_rate(error_rate(row)), fmt_rate(row["false_miss"]), fmt_rate(row["false_hit"]),
            fmt_rate(row["wrong_prim"]), fmt_rate(row["ambiguous"]), fmt_rate(row["self_hits"]),
            fmt_ulp(row["ulp_p50"]), fmt_ulp(row["ulp_p99"]), fmt_ulp(row["ulp_max"]),
            fmt_sig(row["mrays_s"])]


def md_table(header, rows, text_columns):
    """A Markdown table, the first `text_columns` columns left-aligned, numbers right."""
    return (["| " + " | ".join(header) + " |",
             "|" + "|".join("---" if i < text_columns else "---:"
                            for i in range(len(header))) + "|"]
            + ["| " + " | ".join(cells) + " |" for cells in rows] + [""])


def accuracy_table(rows, with_transform=False):
    """Every row, by ray set then backend (file order): the numbers behind the plots."""
    raysets = ordered(r["rayset"] for r in rows)
    backends = ordered(r["backend"] for r in rows)
    transforms = ordered(r["transform"] for r in rows)
    rows = sorted(rows, key=lambda r: (transforms.index(r["transform"]),
                                       raysets.index(r["rayset"]), backends.index(r["backend"])))
    header = (["scale", "offset"] if with_transform else []) + ACCURACY_HEADER
    cells = [([fmt_short(r["scale"]), fmt_offset(r["transform"])] if with_transform else [])
             + accuracy_cells(r) for r in rows]
    return md_table(header, cells, 5 if with_transform else 3)


def image_lines(heading, filename, level):
    return [f"{'#' * level} {heading}", "", f"![{heading}]({filename})", ""]


def scene_pareto_panels(rows):
    """scene -> (base transform, [(panel title, [point])]) for the speed-versus-error plots:
    only the scene as given (its base transform; the sweep's other scales and offsets would
    mix different geometry into one point), one panel per ray-set family and query, each
    backend's rows in a family pooled (rays-weighted error, all rays / total time). Rows
    without a throughput have no place on the speed axis and are left out."""
    scenes = {}
    for scene, transforms in by_scene_transform(rows).items():
        base = base_transform(transforms)
        if base is None:
            continue
        panels = []
        for label, family in group_by(transforms[base], family_label).items():
            label += pooled_words(family)
            points = []
            for backend, group in group_by(family, lambda r: r["backend"]).items():
                error, speed = pooled(group, error_rate), pooled_speed(group)
                if error is not None and speed is not None:
                    points.append({"backend": backend, "error": error, "speed": speed,
                                   "rays": sum(r["rays"] for r in group), "kind": "accuracy"})
            if points:
                panels.append((label, points))
        if panels:
            scenes[scene] = (base, panels)
    return scenes


def accuracy_pareto_plots(acc, colors, used):
    """One speed-versus-error figure per scene of an accuracy file."""
    plots = []
    for scene, (base, panels) in scene_pareto_panels(acc.rows).items():
        heading = scene + ("" if base == IDENTITY else f" ({fmt_transform(base)})")
        title = f"Speed versus error: {heading} ({acc.name}, 1 thread)"
        notes = [ERROR_KINDS["accuracy"][1]]
        plots.append(Plot("Speed versus error", heading, None,
                          unique_name(f"pareto-{safe_name(scene)}", used),
                          lambda path, p=panels, t=title, n=notes: plot_pareto(
                              path, p, colors, t, n)))
    return plots


def error_series(rows, x_of):
    """{backend: [(x, error, rays)]} with each backend's rows at the same x pooled."""
    series = {}
    for (backend, x), group in group_by(rows, lambda r: (r["backend"], x_of(r))).items():
        error = pooled(group, error_rate)
        if error is not None:
            series.setdefault(backend, []).append((x, error, sum(r["rays"] for r in group)))
    return series


def pivot_table(series, x_text, row_header="backend"):
    """The lines of a plot as a table: one row per line, one column per x, error rates."""
    xs = sorted({x for points in series.values() for x, _, _ in points})
    cells = []
    for name, points in series.items():
        at = {x: error for x, error, _ in points}
        cells.append([md_escape(name)] + [fmt_rate(at.get(x)) for x in xs])
    return md_table([row_header] + [x_text(x) for x in xs], cells, 1)


def stability_plots(acc, colors, used):
    """Scenes traced at several scales and/or offsets (the stability sweep): error rate
    against scale, one line per backend, one panel per (ray-set family, offset); a sweep of
    offsets alone is plotted against the offset's distance from the origin instead. Only ray
    sets traced at two transforms or more have a panel (the untransformed scene is the point
    at scale 1, offset 0); the table under the plot lists their rows, and every row of the
    scene at another transform than the one "Results by scene" shows."""
    plots = []
    for scene, transforms in by_scene_transform(acc.rows).items():
        if len(transforms) < 2:
            continue
        base = base_transform(transforms)
        everything = [r for group in transforms.values() for r in group]
        families = group_by(everything, family_label)
        swept = {label for label, family in families.items()
                 if len({r["transform"] for r in family}) > 1}
        rows = [r for r in everything if family_label(r) in swept]
        listed = [r for r in everything if family_label(r) in swept or r["transform"] != base]
        scales = {r["scale"] for r in rows}
        panels, tables = [], []
        for label, family in group_by(rows, family_label).items():
            if len(scales) > 1:
                offsets = group_by(family, offset_text)
                for offset, at_offset in offsets.items():
                    series = error_series(at_offset, lambda r: r["scale"])
                    if series:
                        panels.append((f"{label}, offset {offset}", "scale", series))
                tables += [f"{label}: error rate by scale", ""]
                series = {}
                for offset, at_offset in offsets.items():
                    for backend, points in error_series(at_offset, lambda r: r["scale"]).items():
                        series[f"{backend} at {offset}" if len(offsets) > 1 else backend] = points
                tables += pivot_table(series, lambda v: f"scale {fmt_short(v)}",
                                      "backend at offset" if len(offsets) > 1 else "backend")
            else:
                distance = lambda r: math.hypot(r["offset_x"], r["offset_y"], r["offset_z"])
                series = error_series(family, distance)
                if series:
                    panels.append((label, "offset distance from the origin", series))
                tables += [f"{label}: error rate by offset distance", ""]
                tables += pivot_table(series, lambda v: f"|offset| {fmt_short(v)}")
        if not panels:
            continue
        ncols = min(4, len(group_by(rows, offset_text)) if len(scales) > 1 else 3, len(panels))
        title = (f"Stability sweep: {scene} ({acc.name}), error rate against "
                 + ("scale" if len(scales) > 1 else "offset") + ", one line per backend")
        details = ["<details><summary>" + f"{len(listed):,} rows of the sweep</summary>", ""]
        details += accuracy_table(listed, with_transform=True) + ["</details>", ""]
        plots.append(Plot("Stability under scale and offset", scene, None,
                          unique_name(f"sweep-{safe_name(scene)}", used),
                          lambda path, p=panels, n=ncols, t=title: plot_error_lines(
                              path, p, n, colors, t),
                          extra=tables + details))
    return plots


def parameter_plots(acc, colors, used):
    """Ray sets that differ only in a numeric suffix (far-small-sphere:D=1e2 ... D=1e10):
    error rate against the parameter, one line per backend, one panel per family. This is
    where a kernel's breakdown point shows (EXTREMES G12: the error rate against D)."""
    plots = []
    for scene, transforms in by_scene_transform(acc.rows).items():
        base = base_transform(transforms)
        if base is None:
            continue
        panels, tables = [], []
        parametrised = [r for r in transforms[base] if rayset_parameter(r["rayset"])[1]]
        for label, family in group_by(parametrised, family_label).items():
            names = ordered(rayset_parameter(r["rayset"])[1] for r in family)
            values = {rayset_parameter(r["rayset"])[2] for r in family}
            if len(names) != 1 or len(values) < 2:
                continue
            series = error_series(family, lambda r: rayset_parameter(r["rayset"])[2])
            panels.append((label, names[0], series))
            tables += [f"{label}: error rate by {names[0]}", ""]
            texts = parameter_texts(family)
            tables += pivot_table(series, lambda v, n=names[0], t=texts: f"{n}={t[v]}")
        if not panels:
            continue
        heading = scene + ("" if base == IDENTITY else f" ({fmt_transform(base)})")
        title = (f"Error rate against the ray-set parameter: {heading} ({acc.name}), "
                 "one line per backend")
        plots.append(Plot("Error against a ray-set parameter", heading, None,
                          unique_name(f"parameters-{safe_name(scene)}", used),
                          lambda path, p=panels, t=title: plot_error_lines(
                              path, p, min(3, len(p)), colors, t),
                          extra=tables))
    return plots


def invalid_ray_costs(acc):
    """Per scene (as given) with both an invalid-rays and a control-random ray set, per backend
    timed on both: time per invalid ray / time per valid ray = mrays_s(control) /
    mrays_s(invalid), and false_hit on the invalid rays (the truth for them is a miss)."""
    costs = []
    for scene, transforms in by_scene_transform(acc.rows).items():
        base = base_transform(transforms)
        if base is None:
            continue
        families = group_by(transforms[base], lambda r: (rayset_parameter(r["rayset"])[0],
                                                         r["query"]))
        queries = ordered(q for (_, q) in families)
        for query in queries:
            invalid = group_by(families.get((INVALID_RAYSET, query), []), lambda r: r["backend"])
            control = group_by(families.get((CONTROL_RAYSET, query), []), lambda r: r["backend"])
            for backend in (b for b in invalid if b in control):
                invalid_speed = pooled_speed(invalid[backend])
                control_speed = pooled_speed(control[backend])
                if not invalid_speed or not control_speed:
                    continue
                costs.append({"group": rayset_label(scene, query) if len(queries) > 1 else scene,
                              "backend": backend, "control_speed": control_speed,
                              "invalid_speed": invalid_speed,
                              "slowdown": control_speed / invalid_speed,
                              "false_hit": pooled(invalid[backend], lambda r: r["false_hit"])})
    return costs


def invalid_rays_table(costs):
    """The bars as a table, with the two verdicts spelled out: within Embree's 2.5x bar, and
    every invalid ray answered as a miss."""
    cells = []
    for c in costs:
        within = "yes" if c["slowdown"] <= INVALID_BAR else "**no**"
        if c["false_hit"] is None:
            missed = DASH
        else:
            missed = "yes" if c["false_hit"] == 0 else f"**no**: {fmt_rate(c['false_hit'])} hit"
        cells.append([md_escape(c["group"]), md_escape(c["backend"]),
                      fmt_sig(c["control_speed"]), fmt_sig(c["invalid_speed"]),
                      fmt_sig(c["slowdown"]) + "\u00d7", within, missed])
    header = ["scene", "backend", f"{CONTROL_RAYSET} Mrays/s", f"{INVALID_RAYSET} Mrays/s",
              "invalid / valid time", f"\u2264 {INVALID_BAR:g}\u00d7", "all invalid rays missed"]
    return md_table(header, cells, 2)


def invalid_rays_plot(acc, colors, used):
    costs = invalid_ray_costs(acc)
    if not costs:
        return None
    title = (f"Cost of an invalid ray ({acc.name}, 1 thread)\ntime per {INVALID_RAYSET} ray / "
             f"time per {CONTROL_RAYSET} ray; hatched: answered a hit for some invalid ray")
    return Plot("Invalid rays", "Invalid rays", None,
                unique_name(f"invalid-rays-{safe_name(acc.stem)}", used),
                lambda path, c=costs, t=title: plot_invalid_rays(path, c, colors, t),
                extra=invalid_rays_table(costs))


# ---------------------------------------------------------------------------------------------
# The tessellation study (issue 31): analytic scenes against their triangle stand-ins, and the
# advice within an error budget


def t_error(row):
    """The depth error of a row: |t - t_exact| / t_exact, 99th percentile over the rays both the
    referee and the backend hit (None for occlusion queries and older files)."""
    return row.get("t_relerr_p99")


def resolution(representation):
    """uv<S>x<R> -> triangles per sphere, S (2R - 2): what a stand-in costs; 0 for the analytic
    form, so that it sorts first."""
    match = STAND_IN.match(representation)
    if not match:
        return 0
    return int(match["segments"]) * (2 * int(match["rings"]) - 2)


def fmt_relerr(value):
    """A relative error to two significant digits: 0.017, 1.3e-3, 1e-7."""
    if value is None or math.isnan(value):
        return DASH
    return fmt_short(float(f"{value:.2g}"))


def representation_label(row):
    return row["representation"] or "as loaded"


def results_index(results_rows):
    """(scene, ray set, backend) -> the results row with the fewest threads: build time,
    memory and triangle counts for the study's table (accuracy rows are one thread)."""
    index = {}
    for r in sorted(results_rows, key=lambda r: r["threads"]):
        index.setdefault((r["scene"], r["rayset"], r["backend"]), r)
    return index


def study_points(rows):
    """One point per (backend, representation) of one ray set: error rate, t error, speed."""
    points = []
    for r in rows:
        error = error_rate(r)
        if error is None or not r["mrays_s"]:
            continue
        points.append({"backend": r["backend"], "representation": representation_label(r),
                       "scene": r["scene"], "error": error, "t_error": t_error(r),
                       "speed": r["mrays_s"], "rays": r["rays"], "row": r})
    return points


def tessellation_groups(acc):
    """(scene, [(ray-set label, rows)]) for every scene of an accuracy file with stand-ins: the
    scene's rows and its stand-ins' rows per ray set and query, in file order."""
    groups = []
    for scene in ordered(r["stands_for"] for r in acc.stand_ins):
        rows = [r for r in acc.rows if r["scene"] == scene] + \
               [r for r in acc.stand_ins if r["stands_for"] == scene]
        by_rayset = group_by(rows, lambda r: rayset_label(r["rayset"], r["query"]))
        groups.append((scene, list(by_rayset.items())))
    return groups


def cheapest_within(points, budget):
    """The stand-in with the fewest triangles whose error stays within `budget` for every backend
    that traced it, as (representation, worst error, fastest point there); None if none."""
    stand_ins = group_by([p for p in points if STAND_IN.match(p["representation"])],
                         lambda p: p["representation"])
    for representation in sorted(stand_ins, key=resolution):
        group = stand_ins[representation]
        worst = max(p["error"] for p in group)
        if worst <= budget:
            return representation, worst, max(group, key=lambda p: p["speed"])
    return None


def cheapest_sentence(label, points, budget):
    stand_ins = [p for p in points if STAND_IN.match(p["representation"])]
    if not stand_ins:
        return f"- {label}: no stand-in was timed."
    found = cheapest_within(points, budget)
    if found:
        representation, worst, fastest = found
        return (f"- {label}: **{representation}** is the cheapest tessellation within "
                f"{fmt_rate(budget)} (at most {fmt_rate(worst)} of rays answered wrongly by any "
                f"backend; fastest there {fastest['backend']} at {fmt_sig(fastest['speed'])} "
                "Mrays/s).")
    best = min(stand_ins, key=lambda p: (p["error"], -p["speed"]))
    return (f"- {label}: **no tessellation** stays within {fmt_rate(budget)}: the most accurate "
            f"stand-in, {best['representation']} with {best['backend']}, answers "
            f"{fmt_rate(best['error'])} of rays wrongly.")


def advice(points, budget):
    """The fastest point whose error stays within the budget, or None."""
    within = [p for p in points if p["error"] <= budget]
    return max(within, key=lambda p: (p["speed"], -p["error"])) if within else None


def study_table(rows, index):
    header = ["backend", "representation", "triangles", "Mrays/s", "error", "false miss",
              "false hit", "wrong prim", "t relerr p99", "t relerr max", "ulp p99", "build ms",
              "MiB"]
    backends = ordered(r["backend"] for r in rows)
    rows = sorted(rows, key=lambda r: (backends.index(r["backend"]),
                                       resolution(r["representation"])))
    cells = []
    for r in rows:
        run = index.get((r["scene"], r["rayset"], r["backend"]), {})
        cells.append([md_escape(r["backend"]), md_escape(representation_label(r)),
                      fmt_count(run.get("triangles")) or DASH, fmt_sig(r["mrays_s"]),
                      fmt_rate(error_rate(r)), fmt_rate(r["false_miss"]), fmt_rate(r["false_hit"]),
                      fmt_rate(r["wrong_prim"]), fmt_relerr(t_error(r)), fmt_relerr(r["t_relerr_max"]),
                      fmt_ulp(r["ulp_p99"]), fmt_sig(run.get("build_ms")),
                      fmt_mib(run.get("memory_bytes"))])
    return md_table(header, cells, 2)


def plot_tessellation(path, panels, colors, title, budget):
    """panels: [(ray-set label, [point])]. Per ray set, speed against the wrong-answer rate
    (left) and against the t error (right, closest-hit ray sets only): each backend a colour,
    its stand-ins joined coarse to fine by a line, its analytic form a star."""
    plt = pyplot()
    from matplotlib.lines import Line2D
    fig, axes = plt.subplots(len(panels), 2, figsize=(10.5, 3.6 * len(panels) + 1.0),
                             layout="constrained", squeeze=False)
    backends = ordered(p["backend"] for _, points in panels for p in points)
    for (label, points), (left, right) in zip(panels, axes):
        for ax, key in ((left, "error"), (right, "t_error")):
            shown = [p for p in points if p[key] is not None]
            if not shown:
                ax.set_visible(False)
                continue
            for backend in backends:
                mine = [p for p in shown if p["backend"] == backend]
                line = sorted((p for p in mine if STAND_IN.match(p["representation"])),
                              key=lambda p: resolution(p["representation"]))
                if line:
                    ax.plot([p[key] for p in line], [p["speed"] for p in line], marker="o",
                            markersize=5, markerfacecolor="white", color=colors[backend],
                            linewidth=1.2, zorder=2)
                for p in mine:
                    analytic = not STAND_IN.match(p["representation"])
                    if analytic:
                        ax.scatter([p[key]], [p["speed"]], marker="*", s=140, zorder=3,
                                   color=colors[backend], edgecolors="black", linewidths=0.6)
                    ax.annotate(p["representation"], (p[key], p["speed"]), xytext=(4, 3),
                                textcoords="offset points", fontsize=7, color="0.25")
            values = [p[key] for p in shown]
            if key == "error":
                error_axis(ax, "x", values + ([budget] if budget is not None else []),
                           max(p["rays"] or 0 for p in shown), percent=True)
                ax.set_xlabel("error rate: false miss + false hit + wrong prim (% of rays, symlog)")
                if budget is not None:
                    ax.axvline(budget, color="black", linestyle="--", linewidth=1.0, zorder=1)
            else:
                # Below 1e-7 (a float ulp is 6e-8 to 1.2e-7 relative) the axis is linear.
                positive = [v for v in values if v > 0]
                threshold = 10.0 ** math.floor(math.log10(min(positive + [1e-7])))
                top = max(max(values) * 4, threshold * 100)
                ax.set_xscale("symlog", linthresh=threshold, linscale=1.0)
                ax.set_xlim(-0.6 * threshold, top)
                symlog_ticks(ax.xaxis, threshold, top, MAX_X_LABELS)
                from matplotlib.ticker import FuncFormatter
                ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: fmt_short(v)))
                ax.set_xlabel("t error: |t \u2212 t_exact| / t_exact, p99 (symlog)")
            speeds = [p["speed"] for p in shown]
            if wide_range(speeds, 10):
                log_axis(ax)
                ax.set_ylim(min(speeds) / 1.5, max(speeds) * 1.5)
            else:
                ax.set_ylim(0, max(speeds) * 1.2)
            ax.set_ylabel("throughput (Mrays/s)")
            ax.set_title(label)
            ax.grid(alpha=0.3, zorder=0)
    handles = [Line2D([], [], color=colors[b], marker="o", markerfacecolor="white", label=b)
               for b in backends]
    handles += [Line2D([], [], color="0.3", marker="*", markersize=11, linestyle="none",
                       label="analytic (as loaded)"),
                Line2D([], [], color="0.3", marker="o", markerfacecolor="white",
                       label="stand-ins, coarse to fine")]
    if budget is not None:
        handles.append(Line2D([], [], color="black", linestyle="--",
                              label=f"budget {fmt_rate(budget)}"))
    anchor = next((ax for ax in reversed(list(axes.flat)) if ax.get_visible()), axes.flat[0])
    anchor.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.02, 1.0), frameon=False)
    fig.suptitle(wrap_title(title, fig))
    save(fig, path)


def tessellation_section(acc, colors, used, results_rows, budget):
    """The study of one accuracy file: per scene with stand-ins, its plot, the cheapest
    tessellation within the budget per ray set, and the numbers. ([], []) when it has none."""
    groups = tessellation_groups(acc)
    if not groups:
        return [], []
    index = results_index(results_rows)
    plots, lines = [], ["### Tessellation study", "", TESSELLATION_INTRO, ""]
    if budget is None:
        lines += [NO_BUDGET_LINE, ""]
    for scene, by_rayset in groups:
        panels = [(label, study_points(rows)) for label, rows in by_rayset]
        panels = [(label, points) for label, points in panels if points]
        if not panels:
            continue
        title = (f"Tessellation study: {scene} ({acc.name}, 1 thread): speed against error, "
                 "analytic (star) and stand-ins")
        filename = unique_name(f"tessellation-{safe_name(scene)}", used)
        plots.append(Plot("Tessellation study", scene, None, filename,
                          lambda path, p=panels, t=title: plot_tessellation(
                              path, p, colors, t, budget)))
        lines += image_lines(md_escape(scene), filename, 4)
        if budget is not None:
            lines += [cheapest_sentence(label, points, budget) for label, points in panels] + [""]
        for label, rows in by_rayset:
            lines += [f"{label}:", ""] + study_table(rows, index)
    return plots, lines


def advice_section(acc, budget):
    """Per scene (as given) and ray set: the fastest backend and representation whose error
    stays within the budget, or the most accurate one when none does."""
    lines = [f"### Advice within {fmt_rate(budget)} of rays answered wrongly", "", ADVICE_INTRO, ""]
    cells = []
    for scene, transforms in by_scene_transform(acc.rows).items():
        base = base_transform(transforms)
        if base is None:
            continue
        rows = transforms[base]
        names = {r["scene"] for r in rows}
        rows = rows + [r for r in acc.stand_ins if r["stands_for"] in names]
        heading = scene + ("" if base == IDENTITY else f" ({fmt_transform(base)})")
        for label, group in group_by(rows, lambda r: rayset_label(r["rayset"], r["query"])).items():
            points = study_points(group)
            if not points:
                continue
            best = advice(points, budget)
            if best:
                cells.append([md_escape(heading), md_escape(label), md_escape(best["backend"]),
                              md_escape(best["representation"]), fmt_sig(best["speed"]),
                              fmt_rate(best["error"]), DASH])
            else:
                closest = min(points, key=lambda p: (p["error"], -p["speed"]))
                cells.append([md_escape(heading), md_escape(label), "**none within budget**",
                              DASH, DASH, DASH,
                              f"most accurate: {md_escape(closest['backend'])} "
                              f"{md_escape(closest['representation'])} at "
                              f"{fmt_rate(closest['error'])}"])
    header = ["scene", "ray set", "fastest backend", "representation", "Mrays/s", "error", "note"]
    return lines + md_table(header, cells, 4)


TESSELLATION_INTRO = (
    "Scenes with analytic primitives were also traced as triangle stand-ins "
    "(`<scene>@uv<S>x<R>`: each sphere a UV sphere of S segments by R rings, each box 12 "
    "triangles) with the scene's own rays, judged against the analytic scene's exact referee: "
    "a stand-in triangle's hit counts as a hit on the primitive it stands for. Per ray set, "
    "speed against the error rate (false miss + false hit + wrong prim, % of rays: misses and "
    "hits near silhouettes) and against the t error (|t \u2212 t_exact| / t_exact, 99th "
    "percentile over the rays both hit); each backend's analytic form is a star, its stand-ins "
    "are joined from coarse to fine. The cheapest tessellation is the one with the fewest "
    "triangles whose error stays within the budget for every backend that traced it. Triangles, "
    "build time and memory come from the results CSV when it is given.")
NO_BUDGET_LINE = ("Give `--max-error RATE` (a fraction of rays, e.g. 0.001 for 0.1 %) for the "
                  "cheapest tessellation within that budget and the advice per scene.")
ADVICE_INTRO = (
    "Per scene (as given) and ray set: of every backend and representation traced (the scene "
    "as loaded, and its stand-ins where it has them), the fastest (Mrays/s, one thread) whose "
    "measured error rate (false miss + false hit + wrong prim) stays within the budget; when "
    "none does, the most accurate one is named instead. Untimed rows (the referee) are not "
    "candidates.")


SECTION_INTROS = {
    "Speed versus error": (
        "One figure per scene, one panel per ray set; each point is a backend or kernel "
        "variant: further right = more rays answered wrongly (false miss + false hit + wrong "
        "triangle, % of rays, symlog so that 0 has a place), higher = faster (Mrays/s, one "
        "thread). The dashed line joins the Pareto front (filled points: no other backend is "
        "both faster and more accurate). Ray sets that differ only in a parameter suffix "
        "(`far-small-sphere:D=1e3`) share a panel: their rays pooled, error = wrong rays / all "
        "rays, speed = all rays / total time. Only the scene as given (scale 1, offset 0); the "
        "stability sweep's scaled and moved copies are plotted separately. Rows without a "
        "throughput are left out."),
    "Stability under scale and offset": (
        "Scenes traced at several scales and offsets (every vertex v becomes "
        "float(scale \u00b7 v + offset)): error rate against scale, one line per backend, one "
        "panel per ray set and offset. A line that rises at large scale or offset is a "
        "kernel that is not scale-invariant (absolute epsilons, lost precision far from "
        "the origin)."),
    "Error against a ray-set parameter": (
        "Ray sets that differ only in a numeric suffix (`far-small-sphere:D=1e3`): error rate "
        "against that parameter, one line per backend, one panel per ray-set family."),
    "Invalid rays": (
        f"Per scene with both `{INVALID_RAYSET}` and `{CONTROL_RAYSET}` ray sets: each backend's "
        f"time per invalid ray relative to a valid one, mrays_s({CONTROL_RAYSET}) / "
        f"mrays_s({INVALID_RAYSET}). Embree's bar is at most {INVALID_BAR:g}\u00d7 (dashed); "
        "every invalid ray must be answered as a miss (false hit = 0)."),
}


def miss_only_raysets(rows):
    """(scene, ray set) of the scene as given whose exact truth has no hit in any row."""
    groups = group_by([r for r in rows if r["transform"] == IDENTITY],
                      lambda r: (r["scene"], r["rayset"]))
    return [key for key, group in groups.items()
            if all(r["truth_hits"] is not None and r["truth_hits"] == 0 for r in group)]


def accuracy_summary(acc):
    rows = acc.rows
    scenes = ordered(scene_family(r["scene"]) for r in rows)
    backends = ordered(r["backend"] for r in rows)
    raysets = ordered(r["rayset"] for r in rows)
    lines = [f"- File: `{acc.name}`, {len(rows) + len(acc.stand_ins):,} rows (one thread each)",
             f"- Scenes ({len(scenes)}): " + ", ".join(f"`{s}`" for s in scenes),
             f"- Backends ({len(backends)}): " + ", ".join(f"`{b}`" for b in backends),
             f"- Ray sets ({len(raysets)}): " + ", ".join(f"`{r}`" for r in raysets)]
    if acc.meta:
        lines.append(f"- Metadata: `{os.path.basename(meta_path(acc.path))}`")
        lines += [f"- {label}: {text}" for label, text in run_facts(acc.meta) if text]
    if acc.stand_ins:
        stand_ins = ordered(r["representation"] for r in acc.stand_ins)
        lines.append(f"- Stand-ins ({len(acc.stand_ins):,} rows, in the tessellation study): "
                     + ", ".join(f"`{s}`" for s in sorted(stand_ins, key=resolution)))
    no_hits = miss_only_raysets(rows)
    if no_hits:
        lines.append("- Ray sets with no hit in the exact truth (they can only catch false hits; "
                     "meant so for invalid-rays, behind-origin, degenerate-triangles and "
                     "coplanar): "
                     + ", ".join(f"`{scene} {rayset}`" for scene, rayset in no_hits))
    return lines + [
        "", "Rates are % of the row's rays, judged against the exact referee; truth hits = rays "
        "the referee says hit; error = false "
        "miss + false hit + wrong prim (a hit on a triangle the referee does not accept, "
        "unambiguous rays only). Ambiguous rays lie within rounding of an edge or vertex. Self "
        "hits: secondary rays that hit the primitive they start from. ulp: |t \u2212 t_exact| "
        f"in float ulps at t_exact, over rays both hit. {DASH} = not applicable.", ""]


def accuracy_section(acc, colors, used, results_rows=(), budget=None):
    """The report's part for one accuracy file: its plots (Pareto per scene, stability sweep,
    parameter sweeps, invalid-ray cost), its rows as tables, one per scene, then the
    tessellation study (scenes with stand-ins) and, given a budget, the advice."""
    plots = accuracy_pareto_plots(acc, colors, used)
    plots += stability_plots(acc, colors, used)
    plots += parameter_plots(acc, colors, used)
    invalid = invalid_rays_plot(acc, colors, used)
    plots += [invalid] if invalid else []
    lines = [f"## Accuracy: `{acc.name}`", ""] + accuracy_summary(acc)
    for section in ordered(p.section for p in plots):
        lines += [f"### {section}", "", SECTION_INTROS[section], ""]
        for p in (p for p in plots if p.section == section):
            if p is invalid:
                lines += [f"![{p.heading}]({p.filename})", ""]
            else:
                lines += image_lines(p.heading, p.filename, 4)
            lines += p.extra
    lines += ["### Results by scene", "",
              "The scene as given; the stability sweep's other scales and offsets are listed "
              "under their plot.", ""]
    for scene, transforms in by_scene_transform(acc.rows).items():
        base = base_transform(transforms)
        if base is None:
            continue
        heading = scene + ("" if base == IDENTITY else f" ({fmt_transform(base)})")
        lines += [f"#### {md_escape(heading)}", ""] + accuracy_table(transforms[base])
    study_plots, study_lines = tessellation_section(acc, colors, used, results_rows, budget)
    plots += study_plots
    lines += study_lines
    if budget is not None:
        lines += advice_section(acc, budget)
    return plots, lines


# ---------------------------------------------------------------------------------------------
# Markdown


def run_facts(meta):
    """(label, text) pairs for the Run section, from the metadata raybench writes (all strings);
    keys that are absent are left out, so older or hand-written files still work."""
    m = {key: str(value) for key, value in meta.items() if str(value) != ""}
    cpu = m.get("cpu")
    if cpu and m.get("hardware_threads"):
        cpu += f" ({m['hardware_threads']} hardware threads)"
    commit = m.get("git_commit")
    if commit:
        commit = f"`{commit}`" + (" (uncommitted changes)" if commit.endswith("-dirty") else "")
    rays = m.get("rays")
    if rays and rays.isdigit():
        rays = f"{int(rays):,}"
    reps = m.get("repetitions")
    if reps:
        reps += " timed" + (", interleaved" if m.get("interleaved") == "true" else "")
    return [("Date", m.get("date")),
            ("CPU", cpu),
            ("Host / OS", " / ".join(m[k] for k in ("host", "os") if k in m)),
            ("Compiler", " ".join(m[k] for k in ("compiler", "build_type") if k in m)),
            ("Flags", m.get("flags") and f"`{m['flags']}`"),
            ("Embree", m.get("embree")),
            ("Git commit", commit),
            ("Threads", m.get("threads")),
            ("Rays per ray set", rays),
            ("Repetitions", reps),
            ("Seed", m.get("seed")),
            ("Command", m.get("command") and f"`{m['command']}`")]


def run_section(meta, csv_path, rows):
    lines = ["## Run", "", f"- Results: `{os.path.basename(csv_path)}`"]
    if not meta:
        threads = ", ".join(str(t) for t in sorted(ordered(r["threads"] for r in rows)))
        lines.append(f"- Metadata: none (`{os.path.basename(meta_path(csv_path))}` not found)")
        lines.append(f"- Threads: {threads}")
        return lines + [""]
    lines.append(f"- Metadata: `{os.path.basename(meta_path(csv_path))}`")
    lines += [f"- {label}: {text}" for label, text in run_facts(meta) if text]
    return lines + [""]


TABLE_HEADER = ["scene", "backend", "threads", "Mrays/s [min\u2013max]", "\u00d7 Embree",
                "hit rate", "agree_hit", "agree_prim", "build ms", "MiB"]
# Columns a table has only when its rows fill them (older CSVs lack some; shadow rays have no
# triangle, so no ties and no t): (CSV column, header, format).
OPTIONAL_COLUMNS = [
    ("prim_ties", "ties", lambda v: f"{v:,.0f}"),
    ("t_relerr_max", "t relerr max", fmt_short),
    ("t_relerr_p999", "t relerr p99.9", fmt_short),
    ("leaks", "leaks", lambda v: f"{v:,.0f}"),
]


def table_row(row, optional):
    cells = [md_escape(row["scene"]), md_escape(row["backend"]), str(row["threads"]),
             fmt_throughput(row), fmt_sig(row["ratio_to_embree"]), fmt_percent(row["hit_rate"]),
             fmt_fraction(row["agree_hit"]), fmt_fraction(row["agree_prim"]),
             fmt_sig(row.get("build_ms")), fmt_mib(row.get("memory_bytes"))]
    for column, _, fmt in optional:
        cells.append(DASH if row.get(column) is None else fmt(row[column]))
    return cells


def tables_section(rows, scenes, backends, raysets):
    lines = ["## Tables", "",
             f"Empty cells ({DASH}) are not applicable: occlusion queries report no triangle, "
             "so shadow rays have no agree_prim and no t error. Hit rate is the fraction of rays "
             "the backend reports hit (occluded for shadow rays). Where the CSV has them: ties "
             "counts the rays both hit on which another triangle lies at the same t (a differing "
             "triangle there is no disagreement); t relerr max and p99.9 are the largest and the "
             "99.9th percentile of |t \u2212 t_Embree| / |t_Embree| over the rays both hit; leaks, "
             "on must-hit ray sets only, counts the rays a backend lets through a closed mesh.", ""]
    for rayset in raysets:
        subset = sorted((r for r in rows if r["rayset"] == rayset),
                        key=lambda r: (scenes.index(r["scene"]), r["threads"],
                                       backends.index(r["backend"])))
        optional = [c for c in OPTIONAL_COLUMNS if any(r.get(c[0]) is not None for r in subset)]
        header = TABLE_HEADER + [name for _, name, _ in optional]
        lines += [f"### {rayset_caption(rows, rayset)}", "",
                  "| " + " | ".join(header) + " |",
                  "|" + "|".join("---:" if i >= 3 else "---" for i in range(len(header))) + "|"]
        lines += ["| " + " | ".join(table_row(r, optional)) + " |" for r in subset]
        lines.append("")
    return lines


def plots_section(plots, intro):
    lines = []
    for section in ordered(p.section for p in plots):
        lines += [f"## {section}", ""]
        if intro.get(section):
            lines += [intro[section], ""]
        for p in (p for p in plots if p.section == section):
            lines += [f"### {p.heading}", "", p.sentence, "", f"![{p.heading}]({p.filename})", ""]
    return lines


# Without --accuracy there is no error against ground truth: the report says so, and how to
# get one, in the speed-versus-error section, whether or not any panel is left to draw.
NO_ACCURACY_LINE = ("**No accuracy file given, so no error rates against ground truth.** Make "
                    "one with `raybench run ... --accuracy accuracy.csv` (every ray judged by "
                    "the exact referee; `scripts/accuracy` runs the whole accuracy suite) and "
                    "pass it as `scripts/report RESULTS.csv --accuracy accuracy.csv`. Ray sets "
                    "on which every backend agrees with Embree are not plotted here.")
NO_ACCURACY_STUDY_LINE = (
    "The run traced triangle stand-ins (`<scene>@uv<S>x<R>`; their rows are in the plots and "
    "tables above as scenes of their own), but what they get wrong against the analytic scene "
    "needs its exact referee: run with `--accuracy accuracy.csv` and pass it with "
    "`--accuracy` (and `--max-error RATE` for the advice).")
FALLBACK_ERROR = ("Below, the error is 1 \u2212 agree_hit, disagreement with Embree, not an "
                  "error against ground truth; on must-hit ray sets (a `leaks` value) it is "
                  "leaks / rays, which is one.")


def results_part(csv_path, rows, meta, colors, with_pareto, used):
    """The report's part for the results CSV: Run, throughput and ratio plots, the speed-versus-
    error fallback (when no accuracy file gives real errors), and its tables."""
    scenes = ordered(r["scene"] for r in rows)
    raysets = ordered(r["rayset"] for r in rows)
    backends = results_backends(rows)
    all_threads = sorted(ordered(r["threads"] for r in rows))
    triangles = {r["scene"]: r.get("triangles") for r in rows if r.get("triangles")}
    plots = (throughput_plots(rows, scenes, backends, raysets, all_threads, colors, triangles)
             + ratio_plots(rows, scenes, backends, raysets, all_threads, colors, triangles))
    if with_pareto:
        plots += pareto_plots(error_points_from_results(rows), raysets, colors, triangles, used)
    intro = {"Ratio to Embree": "Ratios are measured within one run (same rays, same machine, "
                                "repetitions interleaved), so they are more stable across runs "
                                "than absolute Mrays/s.",
             "Speed versus error": NO_ACCURACY_LINE + " " + FALLBACK_ERROR}
    lines = run_section(meta, csv_path, rows)
    lines += plots_section(plots, intro)
    if with_pareto and not any(p.section == "Speed versus error" for p in plots):
        lines += ["## Speed versus error", "", NO_ACCURACY_LINE, ""]
    if with_pareto and any(STAND_IN.match(r.get("representation") or "") for r in rows):
        lines += ["## Tessellation study", "", NO_ACCURACY_STUDY_LINE, ""]
    lines += tables_section(rows, scenes, backends, raysets)
    return plots, lines


def results_backends(rows):
    """The reference first, then the order the run listed its backends in."""
    return sorted(ordered(r["backend"] for r in rows), key=lambda b: b != REFERENCE)


# ---------------------------------------------------------------------------------------------
# Output


def write_report(out_dir, plots, markdown):
    """Draw every PNG and report.md in a staging folder inside out_dir, then move them in,
    report.md last: a failure part-way leaves no half-written report.md behind."""
    created = not os.path.isdir(out_dir)
    os.makedirs(out_dir, exist_ok=True)
    stage = tempfile.mkdtemp(prefix=".report-", dir=out_dir)
    try:
        for p in plots:
            p.draw(os.path.join(stage, p.filename))
        with open(os.path.join(stage, "report.md"), "w", encoding="utf-8") as f:
            f.write(markdown)
        for p in plots:
            os.replace(os.path.join(stage, p.filename), os.path.join(out_dir, p.filename))
        os.replace(os.path.join(stage, "report.md"), os.path.join(out_dir, "report.md"))
    except BaseException:
        shutil.rmtree(stage, ignore_errors=True)
        if created and not os.listdir(out_dir):
            os.rmdir(out_dir)
        raise
    shutil.rmtree(stage, ignore_errors=True)


def default_out_dir(csv_path):
    folder, name = os.path.split(os.path.abspath(csv_path))
    return os.path.join(folder, os.path.splitext(name)[0] + "-report")


class Parser(argparse.ArgumentParser):
    """argparse with raybench's one-line error convention instead of usage + message."""

    def error(self, message):
        sys.stderr.write(f"report: error: {message}\n")
        sys.exit(2)


def parse_args(argv):
    parser = Parser(prog="scripts/report", description=__doc__.split("\n\n")[0],
                    epilog="Writes DIR/report.md and PNG plots beside it; see the top of "
                           "scripts/report.py for what each plot shows.")
    parser.add_argument("csv", metavar="RESULTS.csv", nargs="?",
                        help="a raybench results CSV (optional when --accuracy is given)")
    parser.add_argument("--out", metavar="DIR",
                        help="output folder (default: <dir>/<stem>-report/ of RESULTS.csv, "
                             "else of the first --accuracy file)")
    parser.add_argument("--accuracy", metavar="ACCURACY.csv", action="append", default=[],
                        help="an accuracy CSV (results/accuracy.csv, results/accuracy-kernels.csv;"
                             " schema in harness/src/accuracy/accuracy_csv.h); repeat for several "
                             "files. Gives the speed-versus-error plots real errors, and adds the "
                             "stability sweep, ray-set parameter and invalid-ray plots and tables. "
                             "Without it the speed-versus-error plots use 1 - agree_hit "
                             "(disagreement with Embree)")
    parser.add_argument("--title", metavar="TEXT", help="report title")
    parser.add_argument("--max-error", metavar="RATE", type=error_budget,
                        help="an error budget, the fraction of rays a backend may answer wrongly "
                             "(false miss + false hit + wrong prim), e.g. 0.001 for 0.1 %%: the "
                             "tessellation study then names the cheapest tessellation within it, "
                             "and the advice, per scene and ray set, the fastest backend and "
                             "representation within it (needs --accuracy)")
    args = parser.parse_args(argv)
    if args.csv is None and not args.accuracy:
        parser.error("nothing to report: give RESULTS.csv, --accuracy ACCURACY.csv, or both")
    if args.max_error is not None and not args.accuracy:
        parser.error("--max-error needs --accuracy ACCURACY.csv: the error is judged by the "
                     "exact referee (raybench run --accuracy)")
    return args


def error_budget(text):
    """--max-error: a finite fraction in [0, 1]."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not 0.0 <= value <= 1.0:
        raise argparse.ArgumentTypeError(f"expected a fraction of rays from 0 to 1, e.g. 0.001, "
                                         f"got {text!r}")
    return value


def default_title(csv_path, accuracy):
    if csv_path:
        return f"raybench report: {os.path.splitext(os.path.basename(csv_path))[0]}"
    return "raybench accuracy report: " + ", ".join(acc.stem for acc in accuracy)


def main(argv):
    args = parse_args(argv)
    rows = read_table(args.csv, REQUIRED, NUMERIC) if args.csv else []
    meta = read_meta(args.csv) if args.csv else {}
    accuracy = [read_accuracy(path) for path in args.accuracy]
    out_dir = args.out or default_out_dir(args.csv or args.accuracy[0])
    if os.path.exists(out_dir) and not os.path.isdir(out_dir):
        raise InputError(out_dir, "exists and is not a directory")

    # One colour per backend: the results' backends keep theirs in every accuracy figure.
    backends = results_backends(rows)
    used = set()  # PNG names already taken: two scenes may sanitise to the same name
    plots, lines = [], [f"# {args.title or default_title(args.csv, accuracy)}", ""]
    if rows:
        extra = ordered(r["backend"] for acc in accuracy for r in acc.rows
                        if r["backend"] not in backends)
        part_plots, part_lines = results_part(args.csv, rows, meta,
                                              backend_colors(backends + extra), not accuracy, used)
        plots += part_plots
        lines += part_lines
    for acc in accuracy:
        own = ordered(r["backend"] for r in acc.rows if r["backend"] not in backends)
        part_plots, part_lines = accuracy_section(acc, backend_colors(backends + own), used,
                                                  rows, args.max_error)
        plots += part_plots
        lines += part_lines
    write_report(out_dir, plots, "\n".join(lines).rstrip() + "\n")
    print(os.path.join(out_dir, "report.md"))
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv[1:]))
    except InputError as e:
        sys.stderr.write(f"report: error: {e}\n")
        sys.exit(2)
    except OSError as e:
        sys.stderr.write(f"report: error: {e.filename or 'output'}: {e.strerror or e}\n")
        sys.exit(1)
