#!/usr/bin/env python3
"""Broad bad-input probe of the abuopt command line (issue 12, docs/testing.md).

Runs the real binary on a few hundred hostile or unlucky inputs and checks the contract of
`abuopt --help`: every run ends (no hang over --timeout seconds), with exit status 0, 2, 3, 4 or
130 and never a signal, never an internal error text or a sanitizer report, a non-zero exit says
why on stderr, a bad-input exit (2) names what was wrong, a run that ends 0 prints no NaN/inf as a
result, and a run whose output cannot be written (file-size limit standing in for a full disk) is
never exit 0.

The inputs: every scalar value of the shipped configs replaced by hostile tokens (NaN, inf,
negative, zero, huge, text, empty, lists, maps), lines deleted and duplicated, files truncated or
replaced by binary garbage; hostile values of every numeric command-line option; missing,
directory and device paths; output that cannot be written. Which token goes to which key is drawn
from --seed, so a different seed probes different combinations; --cases caps the count.

Usage: bad_input_probe.py ABUOPT_BINARY [--seed S] [--cases N] [--jobs J] [--timeout T]
Run from the repository root (the shipped configs are read from configs/). Exit 0 when every case
keeps the contract, 1 otherwise (each violation printed with its command and output).
"""
import argparse
import concurrent.futures
import os
import random
import re
import resource
import shutil
import signal
import subprocess
import sys
import tempfile
import time

ALLOWED_EXIT = {0, 2, 3, 4, 130}
TOKENS = ["nan", ".nan", "NaN", "inf", ".inf", "-.inf", "-1", "0", "-0.0", "1e308", "-1e308",
          "1e-320", "4294967297", "18446744073709551617", "1.5", "abc", "''", "[]", "{}", "~",
          "true", "0x10", "1e", "--", "&a", "*a", "!!binary AAAA", "'\\x00'", "1_000"]
INTERNAL = re.compile(r"terminate called|Segmentation fault|AddressSanitizer|LeakSanitizer|"
                      r"runtime error:|internal error|std::bad_alloc|Assertion .* failed|"
                      r"what\(\):|core dumped|stack smashing")
NONFINITE = re.compile(r"(?<![A-Za-z_])(-?nan|-?inf)(?![A-Za-z_])", re.IGNORECASE)
SCALAR = re.compile(r"(?P<key>[A-Za-z_][A-Za-z_0-9]*):[ \t]*(?P<val>[^\s,{}\[\]#]+)")

# (command name, shipped config, extra arguments that keep a valid run small; OUT = a fresh dir)
CONFIG_COMMANDS = [
    ("simulate", "configs/report_final_profile.yaml", ["--json"]),
    ("montecarlo", "configs/montecarlo_final_profile.yaml",
     ["--design", "random", "--runs", "12", "--threads", "1", "--json"]),
    ("eqset", "configs/eqset.yaml", ["--freq", "29", "--grid", "12", "--out", "OUT"]),
    ("optimize", "configs/optimize/quick.yaml",
     ["--max-evaluations", "3", "--threads", "1", "--out", "OUT"]),
    ("compare", "configs/compare/benchmarks.yaml", ["--out", "OUT"]),
]

# Numeric options: (command, config, option, fixed arguments)
OPTION_CASES = [
    ("simulate", "configs/report_final_profile.yaml", "--mu", []),
    ("simulate", "configs/report_final_profile.yaml", "--trajectory-interval",
     ["--trajectory", "OUT/traj.csv"]),
    ("simulate", "configs/report_final_profile.yaml", "--beta0", []),
    ("montecarlo", "configs/montecarlo_final_profile.yaml", "--runs", ["--design", "random"]),
    ("montecarlo", "configs/montecarlo_final_profile.yaml", "--grid", []),
    ("montecarlo", "configs/montecarlo_final_profile.yaml", "--seed", ["--design", "random", "--runs", "8"]),
    ("montecarlo", "configs/montecarlo_final_profile.yaml", "--threads", ["--design", "random", "--runs", "8"]),
    ("montecarlo", "configs/montecarlo_final_profile.yaml", "--mu", ["--design", "random", "--runs", "8"]),
    ("montecarlo", "configs/montecarlo_final_profile.yaml", "--design", ["--runs", "8"]),
    ("eqset", "configs/eqset.yaml", "--freq", ["--grid", "12", "--out", "OUT"]),
    ("eqset", "configs/eqset.yaml", "--grid", ["--freq", "29", "--out", "OUT"]),
    ("eqset", "configs/eqset.yaml", "--mu", ["--freq", "29", "--grid", "12", "--out", "OUT"]),
    ("eqset", "configs/eqset.yaml", "--scan", ["--grid", "8"]),
    ("optimize", "configs/optimize/quick.yaml", "--max-evaluations", ["--out", "OUT"]),
    ("optimize", "configs/optimize/quick.yaml", "--threads", ["--max-evaluations", "2", "--out", "OUT"]),
    ("reproduce", None, "--runs", ["--only", "4.1", "--no-plots", "--out", "OUT"]),
    ("reproduce", None, "--only", ["--runs", "16", "--no-plots", "--out", "OUT"]),
    ("reproduce", None, "--threads", ["--only", "4.1", "--runs", "16", "--no-plots", "--out", "OUT"]),
]
OPTION_TOKENS = ["nan", "inf", "-inf", "-1", "0", "1e308", "abc", "", "4294967297",
                 "99999999999999999999", "1,2,3", "0.5,nan", "1:0:0.1", "25:33:0", "4.9", "4.1,9.9", "x"]


class Case:
    def __init__(self, label, args, config_text=None, config_name="config.yaml", fsize=None,
                 expect_failure=False, setup=None):
        self.label = label
        self.args = args
        self.config_text = config_text
        self.config_name = config_name
        self.fsize = fsize
        self.expect_failure = expect_failure
        self.setup = setup


def config_mutations(rng, text):
    """Yields (label, mutated text) for one shipped config."""
    matches = list(SCALAR.finditer(text))
    for m in matches:
        for tok in rng.sample(TOKENS, 4):
            yield (f"{m.group('key')}={tok}", text[:m.start("val")] + tok + text[m.end("val"):])
    lines = text.splitlines(keepends=True)
    content = [i for i, ln in enumerate(lines) if ln.strip() and not ln.lstrip().startswith("#")]
    for i in rng.sample(content, min(4, len(content))):
        yield (f"delete line {i + 1}", "".join(lines[:i] + lines[i + 1:]))
        yield (f"duplicate line {i + 1}", "".join(lines[:i + 1] + [lines[i]] + lines[i + 1:]))
    for cut in rng.sample(range(1, max(2, len(text))), 3):
        yield (f"truncated at byte {cut}", text[:cut])
    yield ("tab indentation", text.replace("  ", "\t"))
    yield ("second document", text + "\n---\nabu: {friction_mu: 0.5}\n")
    yield ("unknown key", text + "\nfrobnicate: 1\n")
    yield ("empty", "")
    yield ("binary garbage", "".join(chr(rng.randrange(0, 256)) for _ in range(200)))
    yield ("deep nesting", "a: " + "[" * 5000 + "]" * 5000 + "\n")
    yield ("huge scalar", "abu:\n  friction_mu: " + "9" * 100000 + "\n")


def build_cases(seed):
    rng = random.Random(seed)
    cases = []
    for cmd, cfg, extra in CONFIG_COMMANDS:
        with open(cfg, encoding="utf-8") as f:
            text = f.read()
        for label, mutated in config_mutations(rng, text):
            cases.append(Case(f"{cmd} {cfg}: {label}", [cmd, "CFG"] + extra, config_text=mutated))
    # A report table file mutated, run through reproduce --configs.
    with open("configs/report/table_4_1.yaml", encoding="utf-8") as f:
        table = f.read()
    for label, mutated in config_mutations(rng, table):
        cases.append(Case(f"reproduce table_4_1.yaml: {label}",
                          ["reproduce", "--configs", "CFGDIR", "--only", "4.1", "--runs", "16",
                           "--no-plots", "--out", "OUT"],
                          config_text=mutated, config_name="table_4_1.yaml"))
    for cmd, cfg, opt, fixed in OPTION_CASES:
        for tok in OPTION_TOKENS:
            args = [cmd] + ([cfg] if cfg else []) + fixed + [opt, tok]
            cases.append(Case(f"{cmd} {opt} {tok!r}", args))
    # Paths: missing, a directory, a device, an unwritable output.
    for cmd, cfg, extra in CONFIG_COMMANDS:
        cases.append(Case(f"{cmd}: missing config", [cmd, "/nonexistent/x.yaml"] + extra))
        cases.append(Case(f"{cmd}: directory as config", [cmd, "configs"] + extra))
        cases.append(Case(f"{cmd}: /dev/null as config", [cmd, "/dev/null"] + extra))
        if "--out" in extra:
            bad = [a if a != "OUT" else "/proc/version/out" for a in extra]
            cases.append(Case(f"{cmd}: output under a file", [cmd, cfg] + bad))
    cases += [
        Case("no subcommand", []), Case("unknown subcommand", ["simulat"]),
        Case("unknown flag", ["montecarlo", "configs/montecarlo_final_profile.yaml", "--rusn", "4"]),
        Case("flag without value", ["montecarlo", "configs/montecarlo_final_profile.yaml", "--runs"]),
        Case("eqset freq and scan", ["eqset", "configs/eqset.yaml", "--freq", "29", "--scan", "25:30:1"]),
        Case("reproduce missing configs dir", ["reproduce", "--configs", "/nonexistent", "--out", "OUT"]),
        Case("archive of garbage", ["optimize", "configs/optimize/quick.yaml", "--max-evaluations", "2",
                                    "--out", "OUT"], setup="garbage_archive"),
    ]
    # Output that cannot be written: a 16 kB file-size limit stands in for a full disk.
    full = [
        ("montecarlo", ["montecarlo", "configs/montecarlo_final_profile.yaml", "--design", "random",
                        "--runs", "1024", "--out", "OUT"]),
        ("reproduce", ["reproduce", "--only", "4.1", "--runs", "1024", "--no-plots", "--out", "OUT"]),
        ("simulate trajectory", ["simulate", "configs/report_final_profile.yaml", "--trajectory",
                                 "OUT/traj.csv"]),
        ("eqset", ["eqset", "configs/eqset.yaml", "--freq", "29", "--grid", "128", "--out", "OUT"]),
        ("optimize", ["optimize", "configs/optimize/quick.yaml", "--max-evaluations", "3", "--out", "OUT"]),
    ]
    for label, args in full:
        cases.append(Case(f"full disk: {label}", args, fsize=16 * 1024, expect_failure=True))
    return cases


def run_case(binary, case, timeout, workdir):
    d = tempfile.mkdtemp(dir=workdir)
    out = os.path.join(d, "out")
    cfg = os.path.join(d, case.config_name)
    if case.config_text is not None:
        with open(cfg, "w", encoding="utf-8", errors="surrogateescape") as f:
            f.write(case.config_text)
    if case.setup == "garbage_archive":
        os.makedirs(out)
        with open(os.path.join(out, "archive.sqlite"), "wb") as f:
            f.write(bytes(random.Random(1).randrange(256) for _ in range(8192)))
    if case.config_name != "config.yaml":
        cfgdir = os.path.join(d, "cfgdir")
        shutil.copytree("configs/report", cfgdir)
        shutil.copy(cfg, os.path.join(cfgdir, case.config_name))
    else:
        cfgdir = d
    args = [binary] + [a.replace("OUT", out).replace("CFGDIR", cfgdir) if a not in ("CFG",) else cfg
                       for a in case.args]

    def limits():
        if case.fsize is not None:
            resource.setrlimit(resource.RLIMIT_FSIZE, (case.fsize, case.fsize))
        os.setsid()

    t0 = time.monotonic()
    p = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, preexec_fn=limits)
    try:
        so, se = p.communicate(timeout=timeout)
        hung = False
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        so, se = p.communicate()
        hung = True
    dt = time.monotonic() - t0
    shutil.rmtree(d, ignore_errors=True)
    return args, p.returncode, so.decode("utf-8", "replace"), se.decode("utf-8", "replace"), dt, hung


def judge(case, rc, so, se, hung):
    problems = []
    if hung:
        problems.append("hang (killed after the timeout)")
    elif rc < 0:
        problems.append(f"killed by signal {-rc}")
    elif rc not in ALLOWED_EXIT:
        problems.append(f"exit status {rc} (allowed: 0, 2, 3, 4, 130)")
    if INTERNAL.search(se) or INTERNAL.search(so):
        problems.append("internal error text or sanitizer report")
    if rc not in (0, None) and not se.strip():
        problems.append("non-zero exit with nothing on stderr")
    # A NaN/inf token accepted with exit 0 went into a text key (a label, a title) and is echoed.
    if rc == 0 and NONFINITE.search(so) and not NONFINITE.search(case.label.split("=", 1)[-1]):
        problems.append("exit 0 with NaN/inf in the output")
    if case.expect_failure and rc == 0:
        problems.append("exit 0 although the output could not be written")
    return problems


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("binary")
    ap.add_argument("--seed", type=int, default=2026)
    ap.add_argument("--cases", type=int, default=0, help="cap on the number of cases (0: all)")
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 2)
    ap.add_argument("--timeout", type=float, default=60.0)
    a = ap.parse_args()
    binary = os.path.abspath(a.binary)
    cases = build_cases(a.seed)
    if a.cases and len(cases) > a.cases:
        cases = random.Random(a.seed).sample(cases, a.cases)
    workdir = tempfile.mkdtemp(prefix="abuopt-probe-")
    counts, bad, slowest = {}, [], (0.0, "")
    t0 = time.monotonic()
    with concurrent.futures.ThreadPoolExecutor(max_workers=a.jobs) as ex:
        futures = {ex.submit(run_case, binary, c, a.timeout, workdir): c for c in cases}
        for fut in concurrent.futures.as_completed(futures):
            c = futures[fut]
            args, rc, so, se, dt, hung = fut.result()
            counts[rc if not hung else "hang"] = counts.get(rc if not hung else "hang", 0) + 1
            slowest = max(slowest, (dt, c.label))
            problems = judge(c, rc, so, se, hung)
            if problems:
                bad.append((c, args, rc, so, se, problems))
    shutil.rmtree(workdir, ignore_errors=True)
    print(f"probe: {len(cases)} cases (seed {a.seed}) in {time.monotonic() - t0:.0f} s; exit statuses: "
          + ", ".join(f"{k}: {v}" for k, v in sorted(counts.items(), key=lambda kv: str(kv[0]))))
    print(f"probe: slowest case {slowest[0]:.1f} s ({slowest[1]})")
    for c, args, rc, so, se, problems in bad:
        print(f"\nVIOLATION [{c.label}]: {'; '.join(problems)}\n  command: {' '.join(args)}\n"
              f"  exit: {rc}\n  stderr: {se.strip()[-600:]}\n  stdout: {so.strip()[-300:]}")
    print(f"probe: {len(bad)} violation(s)")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
