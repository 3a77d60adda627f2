"""Write the conformance matrix as Markdown into docs/conformance.md (issue 30).

Runs every catalogue ship at its design speed and at both ends of its speed range x every
built-in controller x calm water and JONSWAP sea state 5 (steerlab.conformance), and writes
the page docs/conformance.md links from mkdocs.yml. Rerun after changing a law's design rule
or a ship::

    PYTHONPATH=src python3 tools/conformance_table.py                 # docs/conformance.md
    PYTHONPATH=src python3 tools/conformance_table.py --out /tmp/c.md --json /tmp/c.json

A few minutes on two cores from a cold compile cache (each ship-kernel x law-kernel
combination compiles once, then loads from the on-disk cache).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n", 1)[0])
    p.add_argument("--out", default=str(ROOT / "docs" / "conformance.md"), help="the Markdown file to write")
    p.add_argument("--json", default=None, help="also write every case as JSON here")
    p.add_argument("--workers", type=int, default=None, help="processes (default: 2)")
    args = p.parse_args(argv)

    from steerlab.conformance.matrix import run_matrix
    from steerlab.conformance.table import markdown, text_summary
    from steerlab.outputs import dump_json

    def progress(done, n):
        print(f"\r{done}/{n} cases", end="", file=sys.stderr, flush=True)

    m = run_matrix(workers=args.workers, progress=progress)
    print(file=sys.stderr)
    Path(args.out).write_text(markdown(m), encoding="utf-8")
    if args.json:
        dump_json(m.to_dict(), Path(args.json))
    print(text_summary(m))
    print(f"wrote {args.out} ({m.seconds:.0f} s on {m.workers} processes)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
