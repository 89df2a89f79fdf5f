#!/usr/bin/python3
"""ctest: tools/cost_exponent.py fits cost = a N^b to Google Benchmark JSON output.

Synthetic outputs with known exponents, shaped as the two benchmarks write them:
- bench_step_3d (no variant label), per-repetition runs plus their aggregates: the runs are
  fitted, and the aggregates (whose names end in _mean, _median, ...) do not form families;
- the same with --benchmark_report_aggregates_only: the medians are fitted, under the family's
  own name (the tool crashed on this output before);
- bench_step (labelled variants): only the frictional variant is fitted.
Each exponent must come back to 1e-9; the printed table shows it to two decimals, with one
column per N (the median of its repetitions).

    cost_exponent_test.py SOURCE_DIR WORK_DIR
"""
import json
import pathlib
import shutil
import subprocess
import sys

ROOT, WORK = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
sys.path.insert(0, str(ROOT / "tools"))
import cost_exponent  # noqa: E402

failures = []


def expect(ok, what):
    print(("ok    " if ok else "FAIL  ") + what)
    if not ok:
        failures.append(what)


def run(name, n, cpu, label=None, repetitions=0):
    """One benchmark's rows: a single run, or repetitions (cpu times spread +-5 % around cpu,
    median cpu) followed by their mean, median and stddev aggregates."""
    base = {"N": n, "real_time": 1.1 * cpu, "cpu_time": cpu, "time_unit": "ms"}
    if label:
        base["label"] = label
    full = f"{name}/{n}"
    if not repetitions:
        return [dict(base, name=full, run_type="iteration")]
    rows = [dict(base, name=full, run_type="iteration", cpu_time=cpu * f) for f in (0.95, 1.0, 1.05)]
    for agg in ("mean", "median", "stddev"):
        rows.append(dict(base, name=f"{full}_{agg}", run_type="aggregate", aggregate_name=agg,
                         cpu_time=cpu if agg != "stddev" else 0.05 * cpu))
    return rows


def law(a, b, ns):
    return [(n, a * n**b) for n in ns]


SPHERES = {"factorisation": law(2e-3, 1.79, (500, 1000, 2000)),
           "full_step": law(5e-3, 1.6, (500, 1000, 2000))}


def check(data, expected, what):
    path = WORK / f"{what.replace(' ', '_')}.json"
    path.write_text(json.dumps({"context": {}, "benchmarks": data}))
    fams = cost_exponent.families(json.loads(path.read_text()))
    got = {name: cost_exponent.exponent(pts) for name, pts in fams.items()}
    expect(set(got) == set(expected) and all(abs(got[k] - expected[k]) < 1e-9 for k in expected),
           f"{what}: exponents {got} are {expected}")
    p = subprocess.run([sys.executable, str(ROOT / "tools" / "cost_exponent.py"), str(path)],
                       capture_output=True, text=True)
    lines = p.stdout.splitlines()
    printed = {line.split()[0]: line.split()[-1] for line in lines[1:]}
    columns = sorted({n for pts in fams.values() for n, _, _ in pts})
    expect(bool(lines) and lines[0].split()[1:-2] == [f"N={n}" for n in columns],
           f"{what}: one column per N ({lines[:1]})")
    expect(p.returncode == 0 and printed == {k: f"{v:.2f}" for k, v in expected.items()},
           f"{what}: the printed table gives {printed} ({p.stderr.strip()[-200:]})")


def main():
    shutil.rmtree(WORK, ignore_errors=True)
    WORK.mkdir(parents=True)
    expected = {"factorisation": 1.79, "full_step": 1.6}
    check([r for name, pts in SPHERES.items() for n, c in pts for r in run(name, n, c, repetitions=3)],
          expected, "bench_step_3d with repetitions")
    aggregates = [r for name, pts in SPHERES.items() for n, c in pts
                  for r in run(name, n, c, repetitions=3) if r["run_type"] == "aggregate"]
    check(aggregates, expected, "bench_step_3d aggregates only")
    labelled = [r for n, c in law(1e-3, 1.27, (250, 1000, 4000))
                for r in run("factorisation", n, c, label="frictional")]
    labelled += [r for n, c in law(1e-3, 1.9, (250, 1000, 4000))
                 for r in run("factorisation", n, c, label="frictionless")]
    check(labelled, {"factorisation": 1.27}, "bench_step labelled variants")
    (WORK / "none.json").write_text('{"benchmarks": []}')
    p = subprocess.run([sys.executable, str(ROOT / "tools" / "cost_exponent.py"), str(WORK / "none.json")],
                       capture_output=True, text=True)
    expect(p.returncode != 0 and "no benchmark with an N counter" in p.stderr,
           "output without N counters is refused with its reason")
    print(f"{len(failures)} failed")
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
