"""How often would the CI gate fail by noise alone?

Runs the short CI suite (meshes/ci.toml) RUNS times on the same build, then
gates every run against the one before it and against the committed baseline
results/baselines/ci.csv, with the committed thresholds (results/gate.toml),
once on a single run and once as scripts/gate does it: a run that fails is
confirmed with the next, independent run (a failure counts only if both
show it). No code changes between runs, so every failure is a false alarm.
Writes results/noise-experiment.md.

usage: scripts/noise-experiment [RUNS] [--reuse]
  RUNS     default 21 (about 40 s each)
  --reuse  gate the runs already in build/noise/ instead of running again
"""
import datetime
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BUILD = os.environ.get("RAYBENCH_BUILD_DIR", os.path.join(ROOT, "build"))
RAYBENCH = os.path.join(BUILD, "raybench")
BASELINE = os.path.join(ROOT, "results", "baselines", "ci.csv")
CONFIG = os.path.join(ROOT, "results", "gate.toml")
OUT_DIR = os.path.join(BUILD, "noise")
REPORT = os.path.join(ROOT, "results", "noise-experiment.md")


def gate(baseline, current, confirm=None):
    """(passed, failure lines, worst ratio change, its p) for one gate; confirm: a second current run."""
    command = [RAYBENCH, "gate", "--baseline", baseline, "--current", current, "--config", CONFIG]
    if confirm:
        command += ["--current", confirm]
    result = subprocess.run(command, capture_output=True, text=True)
    if result.returncode not in (0, 1):
        sys.exit(f"noise-experiment: error: gate failed to run: {result.stderr.strip()}")
    failures = [line for line in result.stdout.splitlines() if line.startswith("FAIL:")]
    compare = subprocess.run([RAYBENCH, "compare", baseline, current, "--format", "json", "--force"],
                             capture_output=True, text=True, check=True)
    rows = json.loads(compare.stdout)["rows"]
    ratios = [r["ratio_to_embree"] for r in rows if r["ratio_to_embree"]["verdict"] != "-"]
    worst = min(ratios, key=lambda r: r["change"])
    return result.returncode == 0, failures, worst["change"], worst["p_value"]


def main(argv):
    if len(argv) > 1 and argv[1] in ("-h", "--help"):
        print(__doc__)
        return 0
    reuse = "--reuse" in argv
    numbers = [a for a in argv[1:] if a != "--reuse"]
    runs = int(numbers[0]) if numbers else 21
    os.makedirs(OUT_DIR, exist_ok=True)
    suite = os.path.join(ROOT, "meshes", "ci.toml")
    paths = []
    for i in range(runs):
        path = os.path.join(OUT_DIR, f"run-{i:02d}.csv")
        paths.append(path)
        if reuse and os.path.exists(path):
            continue
        print(f"noise-experiment: run {i + 1}/{runs}", file=sys.stderr, flush=True)
        subprocess.run([RAYBENCH, "run", "--suite", suite, "--out", path, "--rays-dir", os.path.join(BUILD, "gate", "rays")],
                       check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    consecutive = [gate(paths[i - 1], paths[i]) for i in range(1, runs)]
    against_baseline = [gate(BASELINE, p) for p in paths]
    # As scripts/gate does it: a failing run is confirmed by the next one.
    confirmed = []
    for i in range(runs - 1):
        single = against_baseline[i]
        confirmed.append(single if single[0] else gate(BASELINE, paths[i], paths[i + 1]))
    with open(os.path.join(ROOT, "results", "baselines", "ci.meta.toml")) as f:
        baseline_meta = f.read()
    cpu = next((line.split("=", 1)[1].strip().strip('"') for line in baseline_meta.splitlines() if line.startswith("cpu")), "?")

    with open(paths[0]) as f:
        row_count = sum(1 for _ in f) - 1

    def summary(name, gates):
        failed = sum(1 for g in gates if not g[0])
        worst = min(g[2] for g in gates)
        return f"| {name} | {len(gates)} | {failed} | {100 * worst:+.1f}% |"

    lines = [
        "# Noise experiment: how often does the CI gate fail by noise alone?",
        "",
        f"Made by `scripts/noise-experiment {runs}` on {datetime.date.today().isoformat()} (CPU: {cpu}, 2 cores, "
        "shared machine). The short CI suite (`meshes/ci.toml`: 4 small scenes, 32,768 rays per ray set, "
        f"9 interleaved repetitions, {row_count} rows) ran "
        f"{runs} times on one build, with no change in between, so every gate failure below is a false alarm. "
        "Thresholds: `results/gate.toml` (ratio to Embree may fall at most 10 %, and only a fall the exact "
        "Mann–Whitney U test calls real at p < 0.01 counts).",
        "",
        "| gates | count | failed | worst ratio change seen |",
        "|---|---:|---:|---:|",
        summary("single run against the run before it", consecutive),
        summary("single run against the committed baseline", against_baseline),
        summary("against the baseline, a failure confirmed by the next run (what `scripts/gate` does)", confirmed),
        "",
        "Per gate, the worst (most negative) change of any row's ratio to Embree, with its p-value:",
        "",
        "| gate | result | worst ratio change | p | failures |",
        "|---|---|---:|---:|---|",
    ]
    for i, g in enumerate(consecutive, start=1):
        lines.append(f"| run {i:02d} vs run {i - 1:02d} | {'pass' if g[0] else 'FAIL'} | {100 * g[2]:+.1f}% | {g[3]:.2g} | "
                     f"{'; '.join(f[6:] for f in g[1]) or '-'} |")
    for i, g in enumerate(against_baseline):
        lines.append(f"| run {i:02d} vs baseline | {'pass' if g[0] else 'FAIL'} | {100 * g[2]:+.1f}% | {g[3]:.2g} | "
                     f"{'; '.join(f[6:] for f in g[1]) or '-'} |")
    for i, g in enumerate(confirmed):
        if not against_baseline[i][0]:
            lines.append(f"| run {i:02d} vs baseline, confirmed by run {i + 1:02d} | {'pass' if g[0] else 'FAIL'} | "
                         f"{100 * g[2]:+.1f}% | {g[3]:.2g} | {'; '.join(f[6:] for f in g[1]) or '-'} |")
    lines += ["",
              "Why confirm: the single-run failures above are one row in one process falling 10-20 % with a tiny p-value "
              "(all 9 interleaved repetitions slower), while the next process is fine. Such per-process effects (memory "
              "placement, a neighbour on the other core) are not averaged away by more repetitions inside one run, but "
              "they do not repeat for the same row in a new process. A real slowdown does, so it still fails.",
              "",
              "Reproduce: `scripts/noise-experiment 21` (about 15 minutes; the runs stay in `build/noise/`; "
              "`--reuse` re-gates them without running again).", ""]
    with open(REPORT + ".tmp", "w") as f:
        f.write("\n".join(lines))
    os.replace(REPORT + ".tmp", REPORT)
    failed = sum(1 for g in confirmed if not g[0])
    print(f"noise-experiment: {failed} of {len(confirmed)} confirmed gates failed "
          f"({sum(1 for g in against_baseline if not g[0])} of {len(against_baseline)} single-run gates); wrote {REPORT}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
