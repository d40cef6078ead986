"""``report.html``: one self-contained page per results folder.

The page puts the question asked first, then the answer, the figures, the table, the notes and
the provenance (``run.json``). It needs nothing but itself: the figures are embedded as data URIs,
the style and the table's sorting are inline, and nothing is fetched, so it opens offline, from an
e-mail, on a phone. A small inline script marks the page once every image has decoded
(``data-images`` on ``<body>``: ``loaded/total``), which the browser test reads. The page is the
template ``templates/report.html.j2`` (jinja2, every value autoescaped); this module only gathers
what it shows.
"""

from __future__ import annotations

import base64
import json
import math
from pathlib import Path

import pandas as pd
from jinja2 import Environment, PackageLoader, StrictUndefined

from foldopt.files import write_atomically
from foldopt.output import drawing

#: Rows of a table that a page shows; the CSV beside it has them all.
MAX_ROWS = 2000

# The page's template, shipped in the package; autoescaping makes every value text, and trimming
# lets a line that holds only a tag leave nothing in the page.
_TEMPLATES = Environment(
    loader=PackageLoader("foldopt.output", "templates"),
    autoescape=True,
    trim_blocks=True,
    lstrip_blocks=True,
    keep_trailing_newline=True,
    undefined=StrictUndefined,
)


def _image(path: Path) -> str:
    data = base64.b64encode(path.read_bytes()).decode("ascii")
    return f"data:image/png;base64,{data}"


def _cell(value) -> tuple[str, str]:
    """Text of a cell and its class (numbers right-aligned, text left)."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "-", ""
    if isinstance(value, float):
        return f"{value:.4g}" if abs(value) < 1e5 else f"{value:.6g}", ""
    if isinstance(value, (int,)) and not isinstance(value, bool):
        return str(value), ""
    return str(value), "text"


def _sortable(table: pd.DataFrame, max_rows: int = MAX_ROWS) -> dict:
    """What the template's sortable table shows of ``table``: its header, at most ``max_rows``
    rows of cells, and a note where rows are left out."""
    shown = table.head(max_rows)
    return {
        "head": [(str(c), "text" if shown[c].dtype == object else "") for c in shown.columns],
        "rows": [[_cell(value) for value in record] for record in shown.itertuples(index=False)],
        "more": (
            f"The first {max_rows:,} of {len(table):,} rows; the CSV holds them all."
            if len(table) > max_rows
            else ""
        ),
    }


def _provenance(provenance: dict) -> dict:
    """``run.json``'s content as the page shows it: the command as typed, the versions, the input
    digest and the resolved study as JSON."""
    command = provenance.get("command")
    study = provenance.get("study")
    return {
        "command": " ".join(command) if isinstance(command, list) else str(command or ""),
        "versions": provenance.get("versions", {}),
        "input_sha256": provenance.get("input_sha256"),
        "study": json.dumps(study, indent=1, default=str) if study else None,
    }


def write_html(
    folder: Path,
    answer,
    figures: list[str],
    table: pd.DataFrame | None = None,
    table_title: str = "Table",
    provenance: dict | None = None,
    designs: bool = False,
) -> Path:
    """Write ``folder/report.html`` atomically: a view of ``answer``, nothing decided here.

    The page is rendered from the template ``foldopt/output/templates/report.html.j2``.

    Parameters
    ----------
    folder : pathlib.Path
        The results folder; ``figures`` are PNG files in it, those drawn by figure workers
        written first (:func:`foldopt.output.drawing.written`).
    answer : foldopt.Answer
        The question, the answer's lines (the terminal's words, notes included), its near-optimal
        range and re-fold schedule (and with ``designs`` its designs compared), first on the page.
    figures : list of str
        File names of the figures, in order; each is embedded as a data URI.
    table : pandas.DataFrame, optional
        Shown sortable (at most :data:`MAX_ROWS` rows).
    table_title : str, default 'Table'
        The table's heading.
    provenance : dict, optional
        ``run.json``'s content: command, versions, input digest, the resolved study.
    designs : bool, default False
        Also show the answer's designs table (where ``table`` is not that table already).

    Returns
    -------
    pathlib.Path
        The page written.
    """
    folder = Path(folder)
    drawing.written()
    page = _TEMPLATES.get_template("report.html.j2").render(
        title=f"foldopt: {answer.title}",
        question=list(answer.question.items()),
        lines=answer.lines(),
        tables=[
            (name, _sortable(shown))
            for name, shown in answer.tables()
            if name != "Designs compared" or designs
        ],
        figures=[(name, _image(folder / name)) for name in figures],
        table=None if table is None else _sortable(table),
        table_title=table_title,
        provenance=_provenance(provenance) if provenance else None,
    )
    return write_atomically(
        folder / "report.html", lambda temporary: temporary.write_text(page, encoding="utf-8")
    )
