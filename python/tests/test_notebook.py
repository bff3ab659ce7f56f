"""The notebook (python/examples/tour.ipynb) runs from start to end with nbclient, and is
committed without outputs."""

import nbformat

from conftest import ROOT, needs

NOTEBOOK = ROOT / "python" / "examples" / "tour.ipynb"


def test_the_notebook_is_committed_without_outputs():
    notebook = nbformat.read(NOTEBOOK, as_version=4)
    for cell in notebook.cells:
        if cell.cell_type == "code":
            assert cell.outputs == [] and cell.execution_count is None, cell.source[:60]


def test_the_notebook_runs():
    nbclient = needs("nbclient")
    needs("matplotlib")
    needs("gymnasium")
    notebook = nbformat.read(NOTEBOOK, as_version=4)
    client = nbclient.NotebookClient(notebook, timeout=600, kernel_name="python3",
                                     resources={"metadata": {"path": str(NOTEBOOK.parent)}})
    client.execute()
    outputs = [o for cell in notebook.cells if cell.cell_type == "code" for o in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    # The pictures: the partition (SVG; the solution itself shows as one too) and two plots.
    data = [o.get("data", {}) for o in outputs]
    assert sum("image/svg+xml" in d for d in data) >= 1
    assert sum("image/png" in d for d in data) == 2
