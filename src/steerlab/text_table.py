"""Tables the CLI prints: aligned columns that fit :data:`MAX_WIDTH` columns, long cells wrapped.

Drawn by `rich <https://rich.readthedocs.io>`_ (imported only when a table is printed) as
plain text: no colours or terminal escapes, so a table reads the same in a terminal, a pipe
and a log file. Cell text is taken literally (``[...]`` is not rich markup).
"""

from __future__ import annotations

import io
import math
import re
import shutil
import sys
from typing import Any, Iterable, Optional, Sequence

MAX_WIDTH = 100   #: widest table [characters]

# rich's SIMPLE_HEAD box in ASCII: one dashed line under the header, nothing else
_BOX = ("    \n"
        "    \n"
        " -- \n"
        "    \n"
        "    \n"
        "    \n"
        "    \n"
        "    \n")


def table_width(limit: int = MAX_WIDTH) -> int:
    """``limit``, or the terminal's width when stdout is a narrower terminal."""
    try:
        if sys.stdout.isatty():
            return max(40, min(limit, shutil.get_terminal_size((limit, 24)).columns))
    except (AttributeError, ValueError):
        pass
    return limit


def cell(value: Any, digits: int = 4) -> str:
    """A cell's text: floats to ``digits`` significant digits (``n/a`` when not finite),
    None as ``-``, everything else by ``str``."""
    if value is None:
        return "-"
    if isinstance(value, bool):
        return str(value)
    if isinstance(value, float):
        return f"{value:.{digits}g}" if math.isfinite(value) else "n/a"
    return str(value)


_NUMBER_TEXT = re.compile(r"[-+]?[\d.]+(?:e[-+]?\d+)?(?:\s*%)?|\[[-+\d.e, ]*\]", re.IGNORECASE)


def _numeric(value: Any) -> bool:
    """True for a number, None, or a short text that reads as one (``"1.5"``, ``"[1, 2]"``, ``"-"``)."""
    if value is None or isinstance(value, (int, float)):
        return True
    text = str(value).strip()
    return text in ("n/a", "-") or (len(text) <= 32 and _NUMBER_TEXT.fullmatch(text) is not None)


def render_table(header: Sequence[str], rows: Iterable[Sequence[Any]], title: Optional[str] = None,
                 align: Optional[str] = None, width: Optional[int] = None, digits: int = 4) -> str:
    """``rows`` under ``header`` as text at most ``width`` columns wide (default
    :func:`table_width`).

    Parameters
    ----------
    header : sequence of str
        Column titles.
    rows : iterable of sequences
        One sequence of cells per row; cells go through :func:`cell`.
    title : str, optional
        A line above the table.
    align : str, optional
        One letter per column, ``"l"`` (left) or ``"r"`` (right); default: left for the first
        column, right for the others.
    width : int, optional
        Widest line [characters].
    digits : int
        Significant digits of float cells.

    Returns
    -------
    str
        The table, lines without trailing blanks, no final newline.
    """
    from rich import box
    from rich.console import Console
    from rich.table import Table
    from rich.text import Text

    width = table_width() if width is None else int(width)
    align = align or ("l" + "r" * (len(header) - 1))
    table = Table(box=box.Box(_BOX, ascii=True), show_edge=False, pad_edge=False, expand=False,
                  title=None if title is None else Text(title), title_justify="left")
    for h, a in zip(header, align):
        table.add_column(Text(h), justify="right" if a == "r" else "left", overflow="fold")
    for row in rows:
        # numbers align on the right in a right-aligned column; prose there reads from the left
        table.add_row(*(Text(cell(v, digits), justify=None if _numeric(v) else "left") for v in row))
    buf = io.StringIO()
    Console(file=buf, width=width, color_system=None, force_terminal=False, no_color=True,
            highlight=False, emoji=False, soft_wrap=False, legacy_windows=False).print(table)
    lines = [line.rstrip() for line in buf.getvalue().splitlines()]
    while lines and not lines[-1]:
        lines.pop()
    while lines and not lines[0]:
        lines.pop(0)
    return "\n".join(lines)


def render_pairs(pairs: Iterable[tuple[str, Any]], title: Optional[str] = None,
                 width: Optional[int] = None, digits: int = 4) -> str:
    """``name  value`` lines (a two-column table without a header line), at most ``width`` wide."""
    from rich import box
    from rich.console import Console
    from rich.table import Table
    from rich.text import Text

    width = table_width() if width is None else int(width)
    table = Table(box=None, show_header=False, show_edge=False, pad_edge=False, expand=False,
                  title=None if title is None else Text(title), title_justify="left")
    table.add_column(overflow="fold")
    table.add_column(overflow="fold")
    for k, v in pairs:
        table.add_row(Text(str(k)), Text(cell(v, digits)))
    buf = io.StringIO()
    Console(file=buf, width=width, color_system=None, force_terminal=False, no_color=True,
            highlight=False, emoji=False, soft_wrap=False, legacy_windows=False).print(table)
    lines = [line.rstrip() for line in buf.getvalue().splitlines()]
    return "\n".join(line for line in lines if line)
