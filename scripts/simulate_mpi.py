#!/usr/bin/env python3
"""Simulates whitted's MPI work queue for N ranks from measured per-tile render times.

Usage:  python3 scripts/simulate_mpi.py OUT_DIR TILE_LOG.csv [TILE_LOG.csv ...]

Each TILE_LOG is what `whitted render --tile-log FILE` writes (one row per tile: tile, x0, y0, x1,
y1, seconds, bytes, the estimated cost the tile was ordered by, and the run's scene, tile_size,
threads, startup seconds). Two orders of the queue are simulated: "frame" (row by row) and "cost"
(the estimate's dearest first, as `--tile-order cost` hands them out). The model, the protocol of
src/session/mpi_frame.cpp:
  - every rank starts after `startup` seconds (MPI_Init + load + accelerator build, measured);
  - ranks 1..N-1 ask rank 0 for BATCH tiles and ask again when half of a batch is left; rank 0
    gives them until their estimated work reaches SHARE / N of the work left (guided: batches
    shrink at the end; the estimate is the log's cost column, 1 per tile in frame order); a request
    and its answer cost 2 * LATENCY plus rank 0's handling time;
  - rank 0 renders too, one tile at a time from the same queue;
  - a finished tile travels to rank 0 in LATENCY + bytes / BANDWIDTH (overlapped with rendering)
    and rank 0 takes PER_TILE_CPU + bytes / MEMCPY seconds to unpack and paste it (serially);
  - a tile renders on any rank in its measured time (one thread, homogeneous hosts).
Efficiency(N) = T(1) / (N * T(N)), T = startup + the last tile pasted. Writes OUT_DIR/mpi_sim.csv
and (with matplotlib) OUT_DIR/mpi_sim.png.
"""
import csv
import heapq
import os
import sys
from collections import defaultdict

LATENCY = 25e-6        # s, one way: 10 GbE with MPI over TCP (InfiniBand: ~2e-6)
BANDWIDTH = 1.25e9     # bytes/s: 10 Gbit/s
PER_TILE_CPU = 5e-6    # s: rank 0's work per message besides the copy
MEMCPY = 5e9           # bytes/s: rank 0's unpack + paste
BATCH = 8              # tiles per request (8 x threads, one thread per rank here)
SHARE = 1 / 16         # a batch's most of the estimated work left, times the ranks (kBatchShare)
STARTUP_EXTRA = 0.34   # s: mpirun + MPI_Init (0.14 s, measured) and the libraries loaded before main (0.2 s)
RANKS = [1, 2, 4, 8, 16, 32, 64, 128, 256]


def simulate(durations, sizes, startup, ranks, costs=None):
    """Makespan of the frame on `ranks` ranks (event simulation of the queue). Batches are guided
    by the estimated work left: `costs` in queue order, or 1 per tile."""
    n = len(durations)
    costs = costs or [1.0] * n
    cost_left = sum(costs)
    next_tile = 0
    t0_busy = startup          # rank 0's comm thread: when it is free to handle the next message
    paste_done = 0.0
    events = []                # (time, kind, rank)
    # Rank 0 renders from the queue directly.
    rank0_free = startup
    # Workers: each holds a local queue; they request at start.
    local = defaultdict(list)
    worker_free = {r: startup for r in range(1, ranks)}
    for r in range(1, ranks):
        heapq.heappush(events, (startup + LATENCY, 0, r))  # request arrives at rank 0
    results = []               # arrival times at rank 0 of finished tiles (with sizes)
    rank0_tiles = []
    pending = set(range(1, ranks))
    # Rank 0's own rendering is interleaved by time: simulate it greedily between events.
    while True:
        # Rank 0 takes a tile whenever it is free and earlier than the next event.
        next_event = events[0][0] if events else float("inf")
        if next_tile < n and rank0_free <= next_event:
            d = durations[next_tile]
            cost_left -= costs[next_tile]
            rank0_tiles.append((rank0_free + d, next_tile))
            rank0_free += d
            next_tile += 1
            continue
        if not events:
            break
        time, kind, r = heapq.heappop(events)
        if kind == 0:  # a request from rank r reaches rank 0
            start = max(time, t0_busy)
            t0_busy = start + PER_TILE_CPU
            batch, budget, got = [], cost_left * SHARE / ranks, 0.0
            while next_tile < n and len(batch) < BATCH and (not batch or got < budget):
                batch.append(next_tile)
                got += costs[next_tile]
                next_tile += 1
            cost_left -= got
            arrive = t0_busy + LATENCY
            heapq.heappush(events, (arrive, 1, r))
            local[r].append(batch)
        elif kind == 1:  # an assignment reaches rank r: it renders its tiles in order
            batch = local[r].pop(0)
            if not batch:
                pending.discard(r)
                continue
            t = max(time, worker_free[r])
            asked = False
            for i, tile in enumerate(batch):
                t += durations[tile]
                results.append((t + LATENCY + sizes[tile] / BANDWIDTH, tile))
                if not asked and i + 1 >= len(batch) // 2:
                    heapq.heappush(events, (t + LATENCY, 0, r))
                    asked = True
            worker_free[r] = t
    # Rank 0 pastes every remote tile serially, as it arrives (its own at once).
    last = max([t for t, _ in rank0_tiles] or [startup])
    busy = startup
    for arrival, tile in sorted(results):
        busy = max(busy, arrival) + PER_TILE_CPU + sizes[tile] / MEMCPY
    return max(last, busy)


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    out_dir = sys.argv[1]
    os.makedirs(out_dir, exist_ok=True)
    runs = defaultdict(lambda: {"tiles": [], "startup": 0.0})
    for path in sys.argv[2:]:
        for row in csv.DictReader(open(path, newline="")):
            key = (row["scene"], int(row["tile_size"]))
            cost = float(row.get("cost") or 0.0)
            runs[key]["tiles"].append((int(row["tile"]), float(row["seconds"]), int(row["bytes"]), cost))
            runs[key]["startup"] = float(row["startup"]) + STARTUP_EXTRA
    orders = {
        "frame": lambda tiles: sorted(tiles),
        "cost": lambda tiles: sorted(tiles, key=lambda t: (-t[3], t[0])),
    }
    rows = []
    for (scene, tile), run in sorted(runs.items()):
        for order, arrange in orders.items():
            queue = arrange(run["tiles"])
            durations = [t[1] for t in queue]
            sizes = [t[2] for t in queue]
            costs = [t[3] for t in queue] if order == "cost" else None
            t1 = simulate(durations, sizes, run["startup"], 1, costs)
            r1 = simulate(durations, sizes, 0.0, 1, costs)
            for n in RANKS:
                tn = simulate(durations, sizes, run["startup"], n, costs)
                rn = simulate(durations, sizes, 0.0, n, costs)  # the render phase alone
                rows.append({"scene": scene, "tile_size": tile, "order": order, "tiles": len(durations), "ranks": n,
                             "seconds": f"{tn:.4f}", "speedup": f"{t1 / tn:.3f}",
                             "efficiency": f"{t1 / (n * tn):.3f}", "render_seconds": f"{rn:.4f}",
                             "render_efficiency": f"{r1 / (n * rn):.3f}"})
    with open(os.path.join(out_dir, "mpi_sim.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    # Mean efficiency over scenes per order, tile size and rank count.
    table = defaultdict(list)
    render_table = defaultdict(list)
    for r in rows:
        key = (r["order"], int(r["tile_size"]), int(r["ranks"]))
        table[key].append(float(r["efficiency"]))
        render_table[key].append(float(r["render_efficiency"]))
    mean = lambda v: sum(v) / len(v)
    tiles = sorted({k[1] for k in table})
    for title, t_ in (("whole run (start-up included)", table), ("render phase alone", render_table)):
        for order in orders:
            print(f"mean efficiency over the scenes, {title}, {order} order (tile size x ranks):")
            print("tile " + " ".join(f"{n:>6}" for n in RANKS))
            for t in tiles:
                print(f"{t:>4} " + " ".join(f"{mean(t_[(order, t, n)]):6.3f}" for n in RANKS))
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib not found: no plot (apt-get install python3-matplotlib)")
        return
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for i, t in enumerate(tiles):
        c = f"C{i}"
        ax.plot(RANKS, [mean(render_table[("cost", t, n)]) for n in RANKS], marker="o", color=c,
                label=f"tile {t} px, render phase, dearest first")
        ax.plot(RANKS, [mean(render_table[("frame", t, n)]) for n in RANKS], marker=".", ls="--", color=c,
                label=f"tile {t} px, render phase, frame order")
        ax.plot(RANKS, [mean(table[("cost", t, n)]) for n in RANKS], ls=":", color=c,
                label=f"tile {t} px, whole run, dearest first")
    ax.set_xscale("log", base=2)
    ax.set_xlabel("ranks (1 thread each)")
    ax.set_ylabel("parallel efficiency T(1) / (N T(N))")
    ax.set_ylim(0, 1.05)
    ax.grid(True, alpha=0.3)
    ax.set_title(f"simulated work queue, mean over {len({k[0] for k in runs})} scenes at 1920x1080")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "mpi_sim.png"), dpi=110)
    print(f"wrote {out_dir}/mpi_sim.csv, {out_dir}/mpi_sim.png")


if __name__ == "__main__":
    main()
