"""The model_uncertainty study (40 runs): its report's summary."""

from _study import produce

if __name__ == "__main__":
    produce(
        "study_model_uncertainty",
        "studies/model_uncertainty.toml",
        "Study: model uncertainty on the tuned environment",
    )
