"""Output: views of an answer, deciding nothing. The results folders
(:mod:`~foldopt.output.folders`: CSV tables, written by :mod:`foldopt.tables`; PNG figures,
:mod:`~foldopt.output.figures`; ``run.json``, :mod:`~foldopt.output.provenance`; ``report.html``,
:mod:`~foldopt.output.html` and its template in ``templates/``) and the columns' vocabulary
(:mod:`~foldopt.output.columns`). Every number shown comes from a result and its
:class:`~foldopt.studies.answer.Answer`. It may import :mod:`foldopt.studies` and everything below
it. No module chooses a matplotlib backend: the plot functions draw on the user's Axes, and files
are drawn on bare figures that need none.
"""
