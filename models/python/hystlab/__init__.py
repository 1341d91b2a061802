"""hystlab from Python: Everett tables, the simplified SMA model, identification, fits and a
client for a running hystlabd (docs/PYTHON.md).

    import numpy as np, hystlab
    table = hystlab.Table.load("T.json")
    model = hystlab.Model(table)
    f = model.evaluate(np.linspace(0, 4, 101))   # the memory is kept between calls

The computation is hystlab's C++ library (the extension hystlab._hystlab, linked statically);
errors carry the messages the CLI prints after "hystlab: error: ". `hystlab.fmu` (an FMU
importer) is imported on its own: `import hystlab.fmu`.
"""
from ._hystlab import (
    FormatError,
    Model,
    Params,
    Table,
    __version__,
    calibrate,
    compare,
    fit,
    identify_from_nodes,
    identify_virtual,
    loop_transformation,
    loops,
    path_work,
)
from .client import ApiError, Client

__all__ = [
    "ApiError",
    "Client",
    "FormatError",
    "Model",
    "Params",
    "Table",
    "__version__",
    "calibrate",
    "compare",
    "fit",
    "identify_from_nodes",
    "identify_virtual",
    "loop_transformation",
    "loops",
    "path_work",
]
