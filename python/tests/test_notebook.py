"""The example notebook (python/examples/bv_tour.ipynb) executed headless
with nbclient: every cell must run without an error and the notebook must
produce figures (PNG outputs of the size bv.render was asked for)."""

import base64
import re
import struct

from conftest import ROOT, need

NOTEBOOK = ROOT / "python" / "examples" / "bv_tour.ipynb"


def png_size(data: bytes):
    assert data.startswith(b"\x89PNG\r\n\x1a\n"), data[:16]
    assert data[12:16] == b"IHDR"
    return struct.unpack(">II", data[16:24])


def test_notebook_runs_and_draws(tmp_path):
    nbformat = need("nbformat")
    nbclient = need("nbclient")
    nb = nbformat.read(NOTEBOOK, as_version=4)
    # Committed without outputs: what runs here is the notebook's own code.
    assert all(not c.get("outputs") for c in nb.cells if c.cell_type == "code")
    client = nbclient.NotebookClient(
        nb, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}}
    )
    # Raises CellExecutionError (the test fails) when any cell errors.
    client.execute()
    errors = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs
              if o.output_type == "error"]
    assert not errors, errors
    sizes = [
        png_size(base64.b64decode(o["data"]["image/png"]))
        for c in nb.cells
        if c.cell_type == "code"
        for o in c.outputs
        if "data" in o and "image/png" in o["data"]
    ]
    assert sizes == [(640, 400), (640, 400)], sizes
    text = "".join(
        o.get("text", "") for c in nb.cells if c.cell_type == "code" for o in c.outputs
    )
    assert "ValueError: parameter `alpha`" in text, text
    assert "peaks at θo" in text, text
    assert re.search(r"θi = +80°  ρ = 0\.\d+", text), text
