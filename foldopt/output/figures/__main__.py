"""``python -m foldopt.output.figures`` prints the manual's table of figures."""

from foldopt.output.figures import rst_table

print(rst_table(), end="")
