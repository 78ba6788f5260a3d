#!/usr/bin/env python3
"""Broad bad-input probe of the abuopt command line (issue 12, docs/testing.md).

Runs the real binary on a few hundred hostile or unlucky inputs and checks the contract of
`abuopt --help`: every run ends (no hang over --timeout seconds), with exit status 0, 2, 3, 4 or
130 and never a signal, never an internal error text or a sanitizer report, a non-zero exit says
why on stderr, a bad-input exit (2) names what was wrong, a run that ends 0 prints no NaN/inf as a
result, and a run whose output cannot be written (file-size limit standing in for a full disk) is
never exit 0.

Round three (issue 29) adds cases with an expected outcome: memory that must not grow with an
allowed value (a 1 GB data limit on a long simulated time), YAML that must not crash or hang
(alias loops, nested aliases, tags, nulls, a FIFO as the config, CR-only line endings), signals
(SIGINT / SIGTERM sent to a running command: exit 130 / 143 within 2 s, saying so), exit statuses
(non-finite option values are bad input, an unwritable output is 4), silent acceptance (empty or
out-of-range option values) and unbounded totals (a limit naming its override).

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

ALLOWED_EXIT = {0, 2, 3, 4, 130, 143}
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
                 expect_failure=False, setup=None, expect_status=None, expect_text=None, forbid_text=None,
                 send_signal=None, signal_at=1.5, data_limit=None, max_seconds=None):
        self.expect_status = expect_status  # the one exit status this case must end with
        self.expect_text = expect_text      # must appear in stdout + stderr
        self.forbid_text = forbid_text      # must not appear
        self.send_signal = send_signal      # sent signal_at s after the start; the run ends within 2 s
        self.signal_at = signal_at
        self.data_limit = data_limit        # RLIMIT_DATA in bytes: memory that grows ends the run
        self.max_seconds = max_seconds      # the case must end within this
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
    cases += round_three_cases()
    return cases


REPORT = "configs/report_final_profile.yaml"
MC = "configs/montecarlo_final_profile.yaml"
SECTIONS = """abu:
  friction_mu: 0.02
profile:
  start_frequency_hz: 0
  segments:
    - {end_frequency_hz: 25.0, duration_s: 1.0}
    - {end_frequency_hz: 29.5, duration_s: 10.0}
    - {end_frequency_hz: 100.0, duration_s: 8.0}
simulation:
  method: event_driven
"""
DESIGN = """montecarlo: {design: lhs, runs: 96, seed: 7}
design:
  segments:
    - end_frequency_hz: {min: 15, max: 28, x0: 25}
      duration_s: {min: 0.3, max: 3, x0: 1}
    - end_frequency_hz: {min: 28, max: 32, x0: 29.5}
      duration_s: {min: 1, max: 12, x0: 10}
    - end_frequency_hz: 100
      duration_s: {min: 1, max: 10, x0: 8}
objective: {kind: mean}
validation: {enabled: false}
optimizer: {algorithm: cobyla, max_evaluations: 40}
"""


def laughs(depth=9, width=10, indent=""):
    text = f"{indent}a0: &a0 [{', '.join(['x'] * width)}]\n"
    for i in range(1, depth + 1):
        text += f"{indent}a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * width)}]\n"
    return text


def round_three_cases():
    """Issue 29: each class with the outcome it must have."""
    c = []
    # 1. memory that grows with an allowed value: 1 GB of data is far above what any of these needs
    for end in ("1.0e5", "1.0e6", "1.0e7"):
        c.append(Case(f"memory: end_time_s {end}", ["simulate", "CFG", "--json"],
                      config_text=SECTIONS.replace("method: event_driven", f"method: event_driven\n  end_time_s: {end}"),
                      expect_status=0, data_limit=1 << 30, max_seconds=20))
    # 2./3. YAML that crashed or hung: one mechanism in the reader
    yaml_cases = [
        ("alias loop in a value", "abu:\n  friction_mu: &a [*a]\n", "refers to the node it is part of"),
        ("alias loop in a section", SECTIONS + "montecarlo: &m {runs: *m}\n", "refers to the node it is part of"),
        ("billion laughs at the top", laughs(), "the limit of a config"),
        ("billion laughs in a value", laughs() + SECTIONS + "montecarlo:\n  runs: *a9\n", "the limit of a config"),
        ("billion laughs in segments", laughs() + "profile:\n  segments: *a9\n", "the limit of a config"),
        ("billion laughs under an unknown key", SECTIONS + "extra:\n" + laughs(indent="  "), "the limit of a config"),
        ("deep alias nesting", laughs(depth=70, width=1), "levels deep"),
        ("unknown tag", SECTIONS + "montecarlo: {runs: !foo 8}\n", "has the YAML tag"),
        ("core tag", "abu:\n  friction_mu: !!float 0.02\n", "has the YAML tag"),
        ("null value", "abu:\n  friction_mu: ~\n", "has no value (null)"),
        ("null ball", "abu:\n  balls:\n    - ~\n    - {mass_kg: 1.4e-4, diameter_m: 3.0e-3}\n", "has no value (null)"),
        ("empty value", "abu:\n  friction_mu:\n", "has no value (null)"),
    ]
    for label, text, expect in yaml_cases:
        c.append(Case(f"yaml: {label}", ["simulate", "CFG"], config_text=text, expect_status=2,
                      expect_text=expect, max_seconds=10))
    c.append(Case("yaml: CR-only line endings", ["simulate", "CFG", "--json"],
                  config_text=SECTIONS.replace("\n", "\r"), expect_status=0))
    c.append(Case("yaml: a FIFO as the config", ["simulate", "FIFO"], setup="fifo", expect_status=2,
                  expect_text="is not a regular file", max_seconds=10))
    # 4. signals: every long command stops within 2 s, says so, exits 130 / 143
    long_runs = [
        ("montecarlo --out", ["montecarlo", MC, "--design", "random", "--runs", "200000", "--out", "OUT"], None),
        ("optimize", ["optimize", "CFG", "--out", "OUT"], SECTIONS + DESIGN),
        ("sweep", ["sweep", "CFG", "--out", "OUT"],
         SECTIONS + DESIGN + "sweep: {method: sobol, variables: [dt2, dt3], points: 64}\n"),
        ("pareto", ["pareto", "CFG", "--out", "OUT"],
         SECTIONS + DESIGN + "pareto: {max_startup_time_s: [18, 14, 12, 10]}\n"),
        ("reproduce", ["reproduce", "--only", "final", "--runs", "40000", "--no-plots", "--out", "OUT"], None),
        ("compare", ["compare", "CFG", "--out", "OUT"],
         "tau: 0.01\nproblems:\n  - label: sp\n    max_evaluations: 20\n    starts: 2\n    seed: 1\n"
         "    startup_profile:\n" + "".join("      " + ln + "\n" for ln in (SECTIONS + DESIGN).splitlines()
                                          if not ln.startswith("optimizer"))
         + "solvers:\n  - {label: COBYLA, algorithm: cobyla}\n  - {label: SBPLX, algorithm: sbplx}\n"),
    ]
    for label, args, text in long_runs:
        for sig, status, name in ((signal.SIGINT, 130, "SIGINT"), (signal.SIGTERM, 143, "SIGTERM")):
            c.append(Case(f"signal: {name} to {label}", args, config_text=text, send_signal=sig,
                          expect_status=status, expect_text=name))
    # 5. exit statuses: non-finite numbers are bad input naming the option; unwritable output is 4
    for tok in ("nan,1", "inf,1", "-inf,1", "nan(0x1),1"):
        c.append(Case(f"exit: --beta0 {tok}", ["simulate", REPORT, "--beta0", tok], expect_status=2,
                      expect_text="--beta0"))
    c.append(Case("exit: eqset --out under a file", ["eqset", "configs/eqset.yaml", "--freq", "29", "--grid", "8",
                                                     "--out", "/proc/version/out"], expect_status=4))
    c.append(Case("exit: archive under a file-size limit", ["sweep", "CFG", "--out", "OUT"],
                  config_text=SECTIONS + DESIGN + "sweep: {method: sobol, variables: [dt2, dt3], points: 4}\n",
                  fsize=4096, expect_status=4, expect_text="cannot write the evaluation archive"))
    # 6. silent acceptance, at the option parser
    for label, args, expect in [
        ("--seed 1e20", ["montecarlo", MC, "--seed", "99999999999999999999"], "--seed"),
        ("--runs ''", ["montecarlo", MC, "--runs", ""], "needs a value"),
        ("--out ''", ["montecarlo", MC, "--out", ""], "needs a value"),
        ("--trajectory ''", ["simulate", REPORT, "--trajectory", ""], "needs a value"),
        ("--scan beyond the cap", ["eqset", "configs/eqset.yaml", "--scan", "1e308:1e308:1"], "1e6"),
    ]:
        c.append(Case(f"silent: {label}", args, expect_status=2, expect_text=expect))
    # 7. unbounded totals: refused at once, naming the override
    c.append(Case("total: reproduce --runs 10000001", ["reproduce", "--runs", "10000001", "--out", "OUT"],
                  expect_status=2, expect_text="--max-total-runs", max_seconds=10))
    bounds = ", ".join(str(5 + i / 100) for i in range(1000))
    c.append(Case("total: pareto with 1000 bounds", ["pareto", "CFG", "--out", "OUT"],
                  config_text=SECTIONS + DESIGN + f"pareto: {{max_startup_time_s: [{bounds}]}}\n",
                  expect_status=2, expect_text="--max-bounds", max_seconds=10))
    # 8. messages
    c.append(Case("message: --mu abc", ["simulate", REPORT, "--mu", "abc"], expect_status=2,
                  forbid_text="not in range"))
    c.append(Case("message: --trajectory-interval x", ["simulate", REPORT, "--trajectory", "OUT/t.csv",
                                                      "--trajectory-interval", "x"], expect_status=2,
                  forbid_text="0" * 40))
    c.append(Case("message: --beta0 4.9e-324,1", ["simulate", REPORT, "--beta0", "4.9e-324,1"], expect_status=0))
    return c


def run_case(binary, case, timeout, workdir):
    d = tempfile.mkdtemp(dir=workdir)
    out = os.path.join(d, "out")
    cfg = os.path.join(d, case.config_name)
    if case.config_text is not None:
        with open(cfg, "w", encoding="utf-8", errors="surrogateescape") as f:
            f.write(case.config_text)
    fifo = os.path.join(d, "config.fifo")
    if case.setup == "fifo":
        os.mkfifo(fifo)
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
    args = [binary] + [a.replace("OUT", out).replace("CFGDIR", cfgdir) if a not in ("CFG", "FIFO")
                       else (cfg if a == "CFG" else fifo) for a in case.args]

    def limits():
        if case.fsize is not None:
            resource.setrlimit(resource.RLIMIT_FSIZE, (case.fsize, case.fsize))
            signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        if case.data_limit is not None:
            resource.setrlimit(resource.RLIMIT_DATA, (case.data_limit, case.data_limit))
        signal.signal(signal.SIGINT, signal.SIG_DFL)
        os.setsid()

    t0 = time.monotonic()
    p = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, preexec_fn=limits)
    case.after_signal = None
    try:
        if case.send_signal is not None:
            try:
                p.wait(timeout=case.signal_at)
            except subprocess.TimeoutExpired:
                sent = time.monotonic()
                p.send_signal(case.send_signal)
                try:
                    p.wait(timeout=timeout)
                    case.after_signal = time.monotonic() - sent
                except subprocess.TimeoutExpired:
                    pass
        so, se = p.communicate(timeout=timeout)
        hung = False
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        so, se = p.communicate()
        hung = True
    dt = time.monotonic() - t0
    case.duration = dt
    shutil.rmtree(d, ignore_errors=True)
    return args, p.returncode, so.decode("utf-8", "replace"), se.decode("utf-8", "replace"), dt, hung


def judge(case, rc, so, se, hung):
    problems = []
    if hung:
        problems.append("hang (killed after the timeout)")
    elif rc < 0:
        problems.append(f"killed by signal {-rc}")
    elif rc not in ALLOWED_EXIT:
        problems.append(f"exit status {rc} (allowed: 0, 2, 3, 4, 130, 143)")
    if INTERNAL.search(se) or INTERNAL.search(so):
        problems.append("internal error text or sanitizer report")
    if rc not in (0, None) and not se.strip():
        problems.append("non-zero exit with nothing on stderr")
    # A NaN/inf token accepted with exit 0 went into a text key (a label, a title) and is echoed.
    if rc == 0 and NONFINITE.search(so) and not NONFINITE.search(case.label.split("=", 1)[-1]):
        problems.append("exit 0 with NaN/inf in the output")
    if case.expect_failure and rc == 0:
        problems.append("exit 0 although the output could not be written")
    text = so + se
    if not hung and case.expect_status is not None and rc != case.expect_status:
        problems.append(f"exit status {rc}, expected {case.expect_status}")
    if case.expect_text and case.expect_text not in text:
        problems.append(f"the output does not say {case.expect_text!r}")
    if case.forbid_text and case.forbid_text in text:
        problems.append(f"the output says {case.forbid_text!r}")
    if case.send_signal is not None and case.after_signal is not None and case.after_signal > 2.0:
        problems.append(f"ended {case.after_signal:.1f} s after the signal (at most 2 s)")
    if case.max_seconds is not None and case.duration > case.max_seconds:
        problems.append(f"took {case.duration:.1f} s (at most {case.max_seconds} s)")
    return problems


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("binary")
    ap.add_argument("--seed", type=int, default=2026)
    ap.add_argument("--cases", type=int, default=0, help="cap on the number of cases (0: all)")
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 2)
    ap.add_argument("--timeout", type=float, default=60.0)
    ap.add_argument("--only", default="", help="run only the cases whose label contains this text")
    a = ap.parse_args()
    binary = os.path.abspath(a.binary)
    cases = [c for c in build_cases(a.seed) if a.only in c.label]
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
