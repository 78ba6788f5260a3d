#!/usr/bin/env python3
"""Cost model of the Monte Carlo over MPI ranks (docs/performance.md, "MPI: cost model").

Simulates the protocol of parallel/src/dispatcher.cpp (one study) event by event: rank 0's threads take guided
chunks (a quarter of the remaining runs per thread, 1..64 runs) from a shared counter; every
other rank asks rank 0 for a chunk for all its threads, runs it on its threads (the rank is free
again when the slowest run of the chunk is done), and asks again with the outcomes. Rank 0's one
dispatcher thread serves the requests one at a time. The run costs are drawn (bootstrap, fixed
seed) from a measured distribution: runs.csv of `abuopt montecarlo --out` (work per run =
rhs_evaluations, calibrated to seconds with the measured CPU time of the whole single-thread run).

  python3 scripts/mpi_cost_model.py RUNS_CSV CPU_SECONDS [--threads T] [--runs N ...]

Standard library only. Prints efficiency E(P) = (single-thread time) / (P * T * makespan) for
P = 1, 2, 16, ..., 1024 ranks, and the parts of the loss.
"""
import argparse
import csv
import heapq
import random


def load_costs(path, cpu_seconds):
    work = [float(r["rhs_evaluations"]) for r in csv.DictReader(open(path))]
    scale = cpu_seconds / sum(work)
    return [w * scale for w in work]


def chunk(left, all_threads):
    return max(1, min(64, left // (4 * all_threads)))


def simulate(costs, ranks, threads, latency, service, per_run, fixed):
    """Makespan of one study: `costs` per run; `latency` one-way message time; `service` and
    `per_run` rank 0's dispatcher time per request and per run in it; `fixed` a serving rank's
    start-up per study (receive the setup, build the simulator)."""
    n = len(costs)
    all_threads = ranks * threads
    nxt = 0
    events = []  # (time, kind, who)
    # rank 0's threads
    for t in range(threads):
        heapq.heappush(events, (0.0, 0, t))
    # serving ranks: first request after the setup arrives and is rebuilt
    for r in range(1, ranks):
        heapq.heappush(events, (latency + fixed + latency, 1, r))
    dispatcher_free = 0.0
    end = 0.0
    while events:
        time, kind, who = heapq.heappop(events)
        end = max(end, time)
        if kind == 0:  # a thread of rank 0 takes a chunk
            if nxt >= n:
                continue
            k = min(chunk(n - nxt, all_threads), n - nxt)
            work = sum(costs[nxt:nxt + k])
            nxt += k
            heapq.heappush(events, (time + work, 0, who))
        else:  # a request of a serving rank reaches rank 0
            start = max(time, dispatcher_free)
            if nxt >= n:
                dispatcher_free = start + service
                continue
            k = min(chunk(n - nxt, all_threads) * threads, n - nxt)
            runs = costs[nxt:nxt + k]
            nxt += k
            dispatcher_free = start + service + per_run * k
            # the chunk on `threads` threads, each taking the next run (list scheduling)
            finish = [0.0] * threads
            for c in runs:
                i = finish.index(min(finish))
                finish[i] += c
            heapq.heappush(events, (dispatcher_free + latency + max(finish) + latency, 1, who))
    return end


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("runs_csv")
    ap.add_argument("cpu_seconds", type=float)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--runs", type=int, nargs="*", default=[4096, 65536])
    ap.add_argument("--latency", type=float, default=5e-6, help="one-way message time [s]")
    ap.add_argument("--service", type=float, default=10e-6, help="dispatcher time per request [s]")
    ap.add_argument("--per-run", type=float, default=2e-6, help="dispatcher time per run [s]")
    ap.add_argument("--fixed", type=float, default=1.2e-3, help="serving rank start-up per study [s]")
    ap.add_argument("--ranks", type=int, nargs="*", default=[1, 2, 16, 32, 64, 128, 256, 512, 1024])
    ap.add_argument("--spread", type=float, default=0.0,
                    help="instead of the measured spread: log-uniform run costs with max/min = SPREAD "
                         "around the measured mean (e.g. 10 for the 10x of issue 11)")
    a = ap.parse_args()
    measured = load_costs(a.runs_csv, a.cpu_seconds)
    if a.spread > 1:
        mean = sum(measured) / len(measured)
        rng = random.Random(2)
        raw = [a.spread ** rng.random() for _ in measured]
        k = mean / (sum(raw) / len(raw))
        measured = [k * r for r in raw]
    mean = sum(measured) / len(measured)
    print(f"measured: {len(measured)} runs, mean {mean * 1e3:.3f} ms, max {max(measured) * 1e3:.3f} ms "
          f"(max/mean {max(measured) / mean:.1f})")
    rng = random.Random(1)
    for n in a.runs:
        costs = [rng.choice(measured) for _ in range(n)]
        serial = sum(costs)
        print(f"\nN = {n} runs, {a.threads} thread(s) per rank, single-thread time {serial:.2f} s")
        print("ranks  makespan_s  efficiency  runs_per_thread")
        for p in a.ranks:
            m = simulate(costs, p, a.threads, a.latency, a.service, a.per_run, a.fixed)
            e = serial / (p * a.threads * m)
            print(f"{p:5d}  {m:10.4f}  {e:10.3f}  {n / (p * a.threads):10.1f}")


if __name__ == "__main__":
    main()
