"""``python -m foldopt``: the command line, as the ``foldopt`` script runs it
(:func:`foldopt.cli.app.main`)."""

from foldopt.cli.app import main

if __name__ == "__main__":  # a tool that imports every module runs no command
    main()
