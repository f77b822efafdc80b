"""Studies at scale: parameter sweeps and Monte Carlo over a base scenario, on Dask.

``load_study(path)`` parses a study file into runs (`spec`); `run_study` executes them on a
``dask.distributed`` cluster into one Parquet table, resumably (`runner`); `write_report`
turns the table into figures and a Markdown summary (`report`). The ``sweep`` and
``report`` subcommands live in `command`.
"""

from uvms_pin.apps.study.reader import load_study
from uvms_pin.apps.study.spec import Parameter, Run, Study
from uvms_pin.errors import StudyError

__all__ = ["Parameter", "Run", "Study", "StudyError", "load_study"]
