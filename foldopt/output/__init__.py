"""Output: views of an answer, deciding nothing. Results folders (CSV tables, PNG figures,
``run.json`` with its provenance, ``report.html``), the columns' vocabulary
(:mod:`~foldopt.output.columns`) and the figures. Every number shown comes from a result and its
:class:`~foldopt.studies.answer.Answer`. It may import :mod:`foldopt.studies` and everything below
it; matplotlib's backend is chosen only when a folder is written, never at import.
"""
