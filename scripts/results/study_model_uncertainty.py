"""The model_uncertainty study (40 runs): its report's summary."""

from _common import producer_cli
from _study import produce

if __name__ == "__main__":
    producer_cli(__doc__)
    produce(
        "study_model_uncertainty",
        "studies/model_uncertainty.toml",
        "Study: model uncertainty on the tuned environment",
    )
