#!/usr/bin/env python3
"""Writes REPORT/summary.md from what scripts/gpu-check.sh run collected, prints it, and exits 1 if anything failed.

    summarize.py --work WORK_DIR --report REPORT_DIR [--rehearsal]

Reads WORK/backends, WORK/suites, WORK/environment.txt, WORK/xml/*.xml (Google Test; the python step's are pytest's
JUnit XML), WORK/time_*, WORK/python.status, WORK/sanitizer_*.status and logs, and from REPORT bench_*.json (Google
Benchmark) and cupy_label.json. Only the Python standard library is used.
"""
import argparse
import glob
import json
import os
import re
import sys
import xml.etree.ElementTree as ET

SANITIZERS = ["memcheck", "racecheck", "synccheck", "initcheck"]
SIZES = ["640x480", "1280x960", "2064x1544", "4128x3088"]


def read(path, default=""):
    try:
        with open(path) as f:
            return f.read()
    except OSError:
        return default


def gtest_results(paths):
    """(passed, failed, skipped, failures[(name, message)]) over Google Test XML files."""
    passed = failed = skipped = 0
    failures = []
    for path in paths:
        try:
            root = ET.parse(path).getroot()
        except (ET.ParseError, OSError) as e:
            failed += 1
            failures.append((os.path.basename(path), f"unreadable result file (the run crashed or timed out?): {e}"))
            continue
        for case in root.iter("testcase"):
            name = f"{case.get('classname')}.{case.get('name')}"
            problems = case.findall("failure") + case.findall("error")
            if problems:
                failed += 1
                message = (problems[0].get("message") or problems[0].text or "").strip().splitlines()
                failures.append((name, message[0] if message else ""))
            elif case.get("result") == "skipped" or case.get("status") == "notrun" or case.find("skipped") is not None:
                skipped += 1
            else:
                passed += 1
    return passed, failed, skipped, failures


def load_bench(path):
    try:
        with open(path) as f:
            return json.load(f).get("benchmarks", [])
    except (OSError, json.JSONDecodeError):
        return None


def ms(value):
    return "" if value is None else f"{value:.4g}" if value < 1000 else f"{value:.0f}"


def bench_table(entries):
    lines = ["| benchmark | frame, wall (ms) | sum of passes (ms) | passes (ms) | dispatches | host waits | segments |",
             "|---|---:|---:|---|---:|---:|---:|"]
    for b in entries:
        if b.get("error_occurred"):
            lines.append(f"| {b['name'].removesuffix('/real_time')} | skipped: {b.get('error_message', '')} | | | | | |")
            continue
        passes = {k[:-3]: v for k, v in b.items() if k.endswith("_ms") and isinstance(v, (int, float))}
        detail = ", ".join(f"{k} {ms(v)}" for k, v in passes.items())
        lines.append(f"| {b['name'].removesuffix('/real_time')} | {ms(b.get('real_time'))} | {ms(sum(passes.values()))} | {detail} | "
                     f"{int(b.get('dispatches', 0))} | {int(b.get('host_syncs', 0))} | {int(b.get('segments', 0))} |")
    return lines


def pass_sum(entry):
    return sum(v for k, v in entry.items() if k.endswith("_ms") and isinstance(v, (int, float)))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--work", required=True)
    ap.add_argument("--report", required=True)
    ap.add_argument("--rehearsal", action="store_true")
    args = ap.parse_args()
    work, report = args.work, args.report
    backends = read(os.path.join(work, "backends")).split()
    env = read(os.path.join(work, "environment.txt"))
    problems = []
    not_run = []
    out = []

    gpu = "no GPU (rehearsal)" if args.rehearsal else "unknown GPU"
    csv = re.search(r"^name, driver_version.*\n(.+)$", env, re.M)
    if csv and not args.rehearsal:
        gpu = csv.group(1).split(",")[0].strip()
    date = re.search(r"^date: (.+)$", env, re.M)
    title = f"# pyrseg GPU check: {gpu}, {date.group(1) if date else ''}"
    if args.rehearsal:
        title = "# pyrseg GPU check REHEARSAL (cpu backend standing in; no GPU was checked)"
    out.append(title)
    out.append("")

    out.append("## Machine")
    for key in ["host", "commit", "prepared", "nvcc", "cuda architectures", "glibc needed"]:
        m = re.search(rf"^{re.escape(key)}: (.+)$", env, re.M)
        if m:
            out.append(f"- {key}: {m.group(1)}")
    if csv:
        header = re.search(r"^(name, driver_version.*)$", env, re.M).group(1)
        out.append(f"- GPU ({header}): {csv.group(1)}")
    m = re.search(r"^--- pyrseg backends\n(.*)", env, re.M | re.S)
    if m:
        out.append("- pyrseg backends:")
        out.append("")
        out.append("```")
        out.extend(m.group(1).rstrip().splitlines())
        out.append("```")
    out.append("")

    out.append("## Conformance (byte-identical to tests/reference)")
    out.append("")
    out.append("| suite | passed | failed | skipped | seconds |")
    out.append("|---|---:|---:|---:|---:|")
    all_failures = []
    suites = read(os.path.join(work, "suites")).split()
    for suite in suites:
        b = suite.removeprefix("conformance_")
        # Not another suite's files whose name starts with this one's (conformance_cuda_graphs_0.xml is not
        # conformance_cuda's).
        longer = [o for o in suites if o != suite and o.startswith(suite + "_")]
        xmls = sorted(x for x in glob.glob(os.path.join(work, "xml", f"{suite}_*.xml"))
                      if not any(os.path.basename(x).startswith(o + "_") for o in longer))
        p, f, s, fails = gtest_results(xmls)
        seconds = read(os.path.join(work, f"time_{suite}")).strip()
        out.append(f"| conformance, {b} | {p} | {f} | {s} | {seconds} |")
        all_failures += fails
        if f:
            problems.append(f"{f} conformance failures on {b}")
        if seconds.startswith("not run"):
            not_run.append(f"conformance on {b} ({seconds[len('not run: '):]})")
        elif p == 0:
            problems.append(f"no conformance test passed on {b}")
    p, f, s, fails = gtest_results(glob.glob(os.path.join(work, "xml", "unit_*.xml")))
    out.append(f"| unit tests, all backends | {p} | {f} | {s} | |")
    all_failures += fails
    if f:
        problems.append(f"{f} unit test failures")
    # The Python module built on this machine against the bundle's shared libraries (gpu-check.sh's run_python):
    # its build, tests/python/smoke.py and the tests of tests/python it runs. On a GPU, test_cuda.py's device-array
    # test must have run: a skip there (no CuPy, CUDA unavailable to the module) is a failure of the check.
    python_status = read(os.path.join(work, "python.status")).strip()
    python_skips = []
    if python_status.startswith("not run"):
        out.append(f"| python module | | | | {python_status} |")
        not_run.append(f"the python module ({python_status[len('not run: '):]})")
    elif python_status:
        xmls = sorted(glob.glob(os.path.join(work, "xml", "python_*.xml")))
        p, f, s, fails = gtest_results(xmls)
        seconds = read(os.path.join(work, "time_python")).strip()
        built = python_status if python_status.startswith("not built") else f"built here: {python_status}"
        out.append(f"| python module ({built}) | {p} | {f} | {s} | {seconds} |")
        all_failures += fails
        if f:
            problems.append(f"{f} python module failures")
        elif p == 0:
            problems.append("no python module test passed")
        device_test = None
        for path in xmls:
            try:
                for case in ET.parse(path).getroot().iter("testcase"):
                    skipped = case.find("skipped")
                    if skipped is not None:
                        name = f"{case.get('classname')}.{case.get('name')}"
                        python_skips.append(f"`{name}`: {skipped.get('message', '')}")
                    if case.get("name") == "test_device_frames_match_host_frames":
                        device_test = "skipped" if skipped is not None else "ran"
            except (ET.ParseError, OSError):
                pass
        if not args.rehearsal and device_test != "ran":
            problems.append("the python module's CUDA device-array test (test_cuda.py) "
                            + ("skipped" if device_test else "did not run") + " on this GPU machine")
    if all_failures:
        out.append("")
        out.append(f"Failures ({len(all_failures)}; first 40, details in conformance.log):")
        out.append("")
        for name, message in all_failures[:40]:
            out.append(f"- `{name}`: {message[:200]}")
    if python_skips:
        out.append("")
        out.append("Python module, skipped:")
        out.append("")
        out.extend(f"- {line[:240]}" for line in python_skips)
    out.append("")

    if not args.rehearsal:
        out.append("## compute-sanitizer (CUDA, a subset of the conformance suite)")
        out.append("")
        out.append("| tool | result | error summary |")
        out.append("|---|---|---|")
        for tool in SANITIZERS:
            status = read(os.path.join(work, f"sanitizer_{tool}.status"), "not run").strip()
            log = read(os.path.join(work, "logs", f"sanitizer_{tool}.log"))
            summary = re.findall(r"ERROR SUMMARY: .*", log)
            out.append(f"| {tool} | {status} | {summary[-1] if summary else ''} |")
            if status in ("errors",) or status.startswith("failed") or status.startswith("timed out"):
                problems.append(f"compute-sanitizer {tool}: {status}")
            elif status != "clean":
                not_run.append(f"compute-sanitizer {tool} ({status})")
        out.append("")

    out.append("## Speed")
    out.append("")
    out.append("Google Benchmark, host pointers in and out (frame, wall: upload, passes, download); per-pass times "
               "from the backend's own timestamps (CUDA events on CUDA).")
    out.append("")
    benches = {}
    for path in sorted(glob.glob(os.path.join(report, "bench_*.json"))):
        name = os.path.basename(path)[:-5]
        entries = load_bench(path)
        if entries is None:
            out.append(f"- {name}: no readable results (the bench failed or timed out: run.log)")
            problems.append(f"{name}: no readable results")
            continue
        benches[name] = entries
        out.append(f"### {name}")
        out.append("")
        out.extend(bench_table(entries))
        out.append("")
    # Names without Google Benchmark's "/real_time" suffix: pipeline/cuda/2064x1544/given_normals, stage/cuda/640x480.
    def named(entries):
        return {b["name"].removesuffix("/real_time"): b for b in entries if not b.get("error_occurred")}
    by_name = {}
    for file, entries in benches.items():
        if "graphs" not in file:
            by_name.update(named(entries))
    graphs = named(benches.get("bench_cuda_graphs", []))
    if graphs:
        out.append("CUDA graphs (PYRSEG_CUDA_GRAPHS=1) against plain launches, the same frames:")
        out.append("")
        out.append("| benchmark | plain, wall (ms) | graphs, wall (ms) | plain, passes (ms) | graphs, passes (ms) |")
        out.append("|---|---:|---:|---:|---:|")
        for name, g in graphs.items():
            plain = by_name.get(name)
            if plain:
                out.append(f"| {name} | {ms(plain['real_time'])} | {ms(g['real_time'])} | {ms(pass_sum(plain))} | "
                           f"{ms(pass_sum(g))} |")
        out.append("")
    scaling = []
    for name, b in by_name.items():
        if "/2064x1544" in name:
            big = by_name.get(name.replace("/2064x1544", "/4128x3088"))
            if big:
                scaling.append(f"| {name.replace('/2064x1544', '')} | {big['real_time'] / b['real_time']:.2f} | "
                               f"{pass_sum(big) / max(pass_sum(b), 1e-9):.2f} |")
    if scaling:
        out.append("4128x3088 against 2064x1544 (4x the pixels):")
        out.append("")
        out.append("| benchmark | wall ratio | passes ratio |")
        out.append("|---|---:|---:|")
        out.extend(scaling)
        out.append("")

    cupy = {}
    try:
        with open(os.path.join(report, "cupy_label.json")) as f:
            cupy = json.load(f)
    except (OSError, json.JSONDecodeError):
        pass
    out.append("## Against cupyx.scipy.ndimage.label (the same fillable mask, 4-connected)")
    out.append("")
    if not cupy.get("available"):
        out.append(f"Not measured: {cupy.get('reason', 'cupy_label.json is missing')}")
        not_run.append("CuPy's label")
    else:
        out.append(f"CuPy {cupy.get('cupy', '')}; its mask is already on the GPU, CUDA events, median of "
                   f"{cupy['masks'][0]['runs'] if cupy.get('masks') else 0} runs.")
        out.append("")
        out.append("| size | backend | pyrseg stage, wall (ms) | pyrseg stage, passes (ms) | CuPy label (ms) | "
                   "CuPy / pyrseg passes | components (CuPy) |")
        out.append("|---|---|---:|---:|---:|---:|---:|")
        for m in cupy.get("masks", []):
            for b in backends:
                stage = by_name.get(f"stage/{b}/{m['size']}")
                if not stage:
                    continue
                passes = pass_sum(stage)
                out.append(f"| {m['size']} | {b} | {ms(stage['real_time'])} | {ms(passes)} | {ms(m['median_ms'])} | "
                           f"{m['median_ms'] / max(passes, 1e-9):.2f} | {m['components']} |")
    out.append("")

    verdict = "FAIL: " + "; ".join(problems) if problems else "PASS: every check that ran passed"
    if not_run:
        verdict += "; not run: " + ", ".join(not_run)
    if args.rehearsal:
        verdict = "REHEARSAL " + verdict + " (cpu backend only)"
    out.insert(2, f"**{verdict}**")
    out.insert(3, "")
    text = "\n".join(out) + "\n"
    with open(os.path.join(report, "summary.md"), "w") as f:
        f.write(text)
    print(text)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
