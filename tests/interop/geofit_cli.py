"""What the interop tests share: the repository root and the geofit binary they drive."""
import os
import subprocess
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]


def geofit_bin():
    """`$GEOFIT_BIN`, else target/release/geofit (built first when missing)."""
    env = os.environ.get("GEOFIT_BIN")
    if env:
        return env
    path = REPO / "target" / "release" / "geofit"
    if not path.exists():
        subprocess.run(["cargo", "build", "--release", "--bin", "geofit"], cwd=REPO, check=True)
    return str(path)
