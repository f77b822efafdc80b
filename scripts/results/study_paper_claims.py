"""The paper_claims study (240 runs): its report's summary."""

from _common import producer_cli
from _study import produce

if __name__ == "__main__":
    producer_cli(__doc__)
    produce("study_paper_claims", "studies/paper_claims.toml", "Study: the paper's claims")
