"""The sea_state study (25 runs, depth x significant height): its report's summary."""

from _common import producer_cli
from _study import produce

if __name__ == "__main__":
    producer_cli(__doc__)
    produce(
        "study_sea_state",
        "studies/sea_state.toml",
        "Study: where the funnels stop holding under waves (depth x Hs)",
    )
