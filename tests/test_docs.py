"""The documentation builds with warnings as errors, running its worked examples, and the example
notebook runs and reproduces the paper's headline numbers."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


def test_docs_build_without_warnings(tmp_path):
    pytest.importorskip("sphinx")
    pytest.importorskip("numpydoc")
    built = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html",
                            "-d", str(tmp_path / "doctrees"), str(ROOT / "docs"), str(tmp_path / "html")],
                           capture_output=True, text=True, timeout=600)
    assert built.returncode == 0, built.stderr[-3000:]
    for page in ("index", "api", "physics", "reproduction", "examples/paper", "examples/weather_year",
                 "examples/design_map"):
        assert (tmp_path / "html" / f"{page}.html").exists(), page
    assert len(list((tmp_path / "html" / "_images").glob("*-1.png"))) == 3  # the examples ran


def test_example_notebook_runs():
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    notebook = nbformat.read(ROOT / "examples" / "paper_headline.ipynb", as_version=4)
    assert len(notebook.cells) < 10
    nbclient.NotebookClient(notebook, timeout=300, kernel_name="python3",
                            resources={"metadata": {"path": str(ROOT)}}).execute()
    printed = "".join(output.get("text", "") for cell in notebook.cells if cell.cell_type == "code"
                      for output in cell.get("outputs", []))
    assert "best fold angle: paper 29.8 deg, foldopt 28.5 deg" in printed
