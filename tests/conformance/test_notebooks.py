"""Every notebook in notebooks/ runs top to bottom (nbclient), so the walkthroughs stay true."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from tests.support.paths import ROOT

NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_notebook_runs(path: Path, tmp_path: Path) -> None:
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    nb = nbformat.read(path, as_version=4)
    for module in nb.metadata.get("chaingeo", {}).get("requires", []):
        pytest.importorskip(module, reason=f"{path.name} needs {module}")
    env_before = os.environ.get("CHAIN_NOTEBOOK_TMP")
    os.environ["CHAIN_NOTEBOOK_TMP"] = str(tmp_path)  # notebooks write their runs here
    try:
        client = nbclient.NotebookClient(
            nb, timeout=300, kernel_name="python3", resources={"metadata": {"path": str(ROOT)}}
        )
        client.execute()
    finally:
        if env_before is None:
            os.environ.pop("CHAIN_NOTEBOOK_TMP", None)
        else:
            os.environ["CHAIN_NOTEBOOK_TMP"] = env_before
    errors = [
        out
        for cell in nb.cells
        if cell.cell_type == "code"
        for out in cell.get("outputs", [])
        if out.get("output_type") == "error"
    ]
    assert not errors
