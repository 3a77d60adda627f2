#!/usr/bin/env python
"""kill -9 at 50 random points of ``steerlab run``, ``montecarlo`` and ``tune``: the table of
docs/reliability-outputs.md.

Usage::

    python benchmarks/kill_points.py                   # 50 kill points per command
    python benchmarks/kill_points.py --points 10 --commands run --json

Method: tests/kill_harness.py (old result = seed 1 copied into --out, new = seed 2 started and
SIGKILLed after a seeded random delay; then the repair the next run does first). Columns:
``old`` / ``new`` / ``missing``: what --out held right after the kill (``missing``: between the
two renames of the swap); ``stage left`` / ``old left``: kills that left a stage folder (killed
while writing) or a replaced folder (killed in the swap); ``finished``: runs that ended before
their kill; ``after repair``: --out after the next run's repair (must be old or new);
``leftovers``: sibling folders still there after it (must be 0); ``failures``: kill points that
broke all-or-nothing (must be 0). Exit code 1 if any failed.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "src"))

from kill_harness import COMMANDS, Case, check, delays  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--points", type=int, default=50)
    ap.add_argument("--commands", default=",".join(COMMANDS))
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args(argv)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for command in args.commands.split(","):
            case = Case(command, Path(tmp))
            case.prepare(real_old=True, find_volatile=True)
            results = []
            for i, d in enumerate(delays(args.points, case.run_s, args.seed + sum(map(ord, command)))):
                results.append(case.kill_at(d))
                print(f"{command}: {i + 1}/{args.points} kill at {d:.2f} s -> {results[-1]['before']}",
                      file=sys.stderr, flush=True)
            before = Counter(r["before"] for r in results)
            after = Counter(r["after"] for r in results)
            rows.append({"command": command, "run_s": round(case.run_s, 2), "kills": len(results),
                         "finished": sum(r["finished"] for r in results),
                         "old": before["old"], "new": before["new"], "missing": before["missing"],
                         "stage_left": sum(r["stage_left"] for r in results),
                         "old_left": sum(r["old_left"] for r in results),
                         "after_old": after["old"], "after_new": after["new"],
                         "leftovers": sum(bool(r["leftovers_after"]) for r in results),
                         "failures": sum(bool(check(r)) for r in results)})
    if args.json:
        print(json.dumps(rows, indent=2))
    else:
        head = ("command", "run s", "kills", "finished", "old", "new", "missing", "stage left", "old left",
                "after repair old/new", "leftovers", "failures")
        print("| " + " | ".join(head) + " |")
        print("|" + "---|" * len(head))
        for r in rows:
            print(f"| {r['command']} | {r['run_s']} | {r['kills']} | {r['finished']} | {r['old']} | {r['new']} | "
                  f"{r['missing']} | {r['stage_left']} | {r['old_left']} | {r['after_old']}/{r['after_new']} | "
                  f"{r['leftovers']} | {r['failures']} |")
    return 1 if any(r["failures"] for r in rows) else 0


if __name__ == "__main__":
    sys.exit(main())
