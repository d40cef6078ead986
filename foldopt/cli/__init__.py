"""The command line: a thin shell over :mod:`foldopt.api`. Options are declared once and shared by
the commands that take them; the commands parse arguments, call the library, print the answer it
returns and set the exit code (2 for bad input, one ``error:`` line per fault, no traceback). It
may import anything below it, and keeps heavy imports (numpy, pandas, pvlib, matplotlib) out of
``--help`` and input checks.
"""
