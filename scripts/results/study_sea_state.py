"""The sea_state study (25 runs, depth x significant height): its report's summary."""

from _study import produce

if __name__ == "__main__":
    produce(
        "study_sea_state",
        "studies/sea_state.toml",
        "Study: where the funnels stop holding under waves (depth x Hs)",
    )
