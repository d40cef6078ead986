"""``report.html``: one self-contained page per results folder.

The page puts the question asked first, then the answer, the figures, the table, the notes and
the provenance (``run.json``). It needs nothing but itself: the figures are embedded as data URIs,
the style and the table's sorting are inline, and nothing is fetched, so it opens offline, from an
e-mail, on a phone. A small inline script marks the page once every image has decoded
(``data-images`` on ``<body>``: ``loaded/total``), which the browser test reads.
"""

from __future__ import annotations

import base64
import html
import json
from pathlib import Path

import pandas as pd

from foldopt.files import write_atomically

#: Rows of a table that a page shows; the CSV beside it has them all.
MAX_ROWS = 2000

_STYLE = """
:root { color-scheme: light; --accent: #1f77b4; --muted: #666; }
* { box-sizing: border-box; }
body { font: 15px/1.45 system-ui, -apple-system, "Segoe UI", Roboto, sans-serif; margin: 0 auto; padding: 12px;
       max-width: 1100px; color: #222; }
h1 { font-size: 1.4em; margin: 0.2em 0; } h2 { font-size: 1.15em; margin: 1.4em 0 0.4em; }
.question { display: grid; grid-template-columns: max-content 1fr; gap: 2px 12px; margin: 0.5em 0; }
.question dt { color: var(--muted); } .question dd { margin: 0; }
.answer { background: #eef5fb; border-left: 4px solid var(--accent); padding: 8px 12px; margin: 0.8em 0; }
.answer p { margin: 0.25em 0; }
figure { margin: 0.8em 0; } figure img { max-width: 100%; height: auto; border: 1px solid #ddd; }
figcaption { color: var(--muted); font-size: 0.9em; }
.scroll { overflow-x: auto; max-height: 70vh; overflow-y: auto; border: 1px solid #ddd; }
table { border-collapse: collapse; font-size: 0.85em; white-space: nowrap; }
th, td { padding: 3px 8px; border-bottom: 1px solid #eee; text-align: right; }
th { position: sticky; top: 0; background: #f4f4f4; cursor: pointer; user-select: none; }
th[aria-sort="ascending"]::after { content: " \\25B2"; } th[aria-sort="descending"]::after { content: " \\25BC"; }
td.text, th.text { text-align: left; }
pre { background: #f7f7f7; padding: 8px; overflow-x: auto; font-size: 0.8em; }
.muted { color: var(--muted); font-size: 0.9em; }
"""

_SCRIPT = """
function sortTable(th) {
  const table = th.closest('table'), body = table.tBodies[0], index = th.cellIndex;
  const ascending = th.getAttribute('aria-sort') !== 'ascending';
  for (const other of th.parentNode.children) other.removeAttribute('aria-sort');
  th.setAttribute('aria-sort', ascending ? 'ascending' : 'descending');
  const key = row => { const text = row.cells[index].textContent.trim(); const number = parseFloat(text);
                       return text === '' || text === '-' ? null : (isNaN(number) ? text : number); };
  const rows = Array.from(body.rows);
  rows.sort((a, b) => { const x = key(a), y = key(b);
    if (x === null) return 1; if (y === null) return -1;
    const order = typeof x === 'number' && typeof y === 'number' ? x - y : String(x).localeCompare(String(y));
    return ascending ? order : -order; });
  for (const row of rows) body.appendChild(row);
}
document.querySelectorAll('th').forEach(th => th.addEventListener('click', () => sortTable(th)));
window.addEventListener('load', () => {
  const images = Array.from(document.images);
  const loaded = images.filter(image => image.complete && image.naturalWidth > 0).length;
  document.body.dataset.images = loaded + '/' + images.length;
});
"""


def _image(path: Path) -> str:
    data = base64.b64encode(path.read_bytes()).decode("ascii")
    return f"data:image/png;base64,{data}"


def _cell(value) -> tuple[str, str]:
    """Text of a cell and its class (numbers right-aligned, text left)."""
    if value is None or (isinstance(value, float) and value != value):
        return "-", ""
    if isinstance(value, float):
        return f"{value:.4g}" if abs(value) < 1e5 else f"{value:.6g}", ""
    if isinstance(value, (int,)) and not isinstance(value, bool):
        return str(value), ""
    return html.escape(str(value)), "text"


def table_html(table: pd.DataFrame, max_rows: int = MAX_ROWS) -> str:
    """A sortable HTML table (click a header) of at most ``max_rows`` rows."""
    shown = table.head(max_rows)
    head = "".join(f'<th class="{"text" if shown[c].dtype == object else ""}">{html.escape(str(c))}</th>'
                   for c in shown.columns)
    rows = []
    for record in shown.itertuples(index=False):
        cells = [_cell(value) for value in record]
        rows.append("<tr>" + "".join(f'<td class="{cls}">{text}</td>' for text, cls in cells) + "</tr>")
    more = (f'<p class="muted">The first {max_rows:,} of {len(table):,} rows; the CSV holds them all.</p>'
            if len(table) > max_rows else "")
    return f'<div class="scroll"><table><thead><tr>{head}</tr></thead><tbody>{"".join(rows)}</tbody></table></div>{more}'


def write_html(folder: Path, answer, figures: list[str], table: pd.DataFrame | None = None,
               table_title: str = "Table", provenance: dict | None = None, designs: bool = False) -> Path:
    """Write ``folder/report.html`` atomically: a view of ``answer``, nothing decided here.

    Parameters
    ----------
    folder : pathlib.Path
        The results folder; ``figures`` are PNG files in it.
    answer : foldopt.studies.answer.Answer
        The question, the answer's lines (the terminal's words, notes included), its near-optimal
        range and re-fold schedule (and with ``designs`` its designs compared), first on the page.
    figures : list of str
        File names of the figures, in order.
    table : pandas.DataFrame, optional
        Shown sortable (at most :data:`MAX_ROWS` rows).
    table_title : str
    provenance : dict, optional
        ``run.json``'s content: command, versions, input digest.
    designs : bool
        Also show the answer's designs table (where ``table`` is not that table already).

    Returns
    -------
    pathlib.Path
    """
    folder = Path(folder)
    title = f"foldopt: {answer.title}"
    parts = [f"<h1>{html.escape(title)}</h1>", '<dl class="question">']
    for label, value in answer.question.items():
        parts.append(f"<dt>{html.escape(str(label))}</dt><dd>{html.escape(str(value))}</dd>")
    parts.append("</dl>")
    parts.append('<section class="answer"><h2>Answer</h2>'
                 + "".join(f"<p>{html.escape(line)}</p>" for line in answer.lines()) + "</section>")
    for name, shown in answer.tables():
        if name != "Designs compared" or designs:
            parts.append(f'<h2>{html.escape(name)}</h2>{table_html(shown)}')
    if figures:
        parts.append("<h2>Figures</h2>")
        for name in figures:
            parts.append(f'<figure><img src="{_image(folder / name)}" alt="{html.escape(name)}" loading="eager">'
                         f"<figcaption>{html.escape(name)}</figcaption></figure>")
    if table is not None:
        parts.append(f"<h2>{html.escape(table_title)}</h2>")
        parts.append(table_html(table))
    if provenance:
        command = provenance.get("command")
        shown = " ".join(command) if isinstance(command, list) else str(command or "")
        versions = provenance.get("versions", {})
        parts.append("<h2>Provenance</h2>")
        parts.append(f'<p class="muted">Command: <code>{html.escape(shown)}</code></p>')
        parts.append('<p class="muted">' + html.escape(", ".join(f"{k} {v}" for k, v in versions.items())) + "</p>")
        if provenance.get("input_sha256"):
            parts.append(f'<p class="muted">Inputs SHA-256: <code>{provenance["input_sha256"]}</code></p>')
        study = provenance.get("study")
        if study:
            parts.append("<details><summary>The resolved study</summary><pre>"
                         + html.escape(json.dumps(study, indent=1, default=str)) + "</pre></details>")
    page = ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            '<meta name="viewport" content="width=device-width, initial-scale=1">'
            f"<title>{html.escape(title)}</title><style>{_STYLE}</style></head>\n<body>\n"
            + "\n".join(parts) + f"\n<script>{_SCRIPT}</script>\n</body></html>\n")
    return write_atomically(folder / "report.html", lambda temporary: temporary.write_text(page, encoding="utf-8"))
