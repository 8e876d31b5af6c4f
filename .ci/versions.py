"""Print the versions this environment resolved for robocfg's direct dependencies and what moved
since `.ci/tested-versions.txt` (the set the suite last passed with). Drift is printed, not fatal:
CI tests the newest versions the pyproject bounds allow, so a red run after drift points here.

    python .ci/versions.py            # report
    python .ci/versions.py --write    # record the current set as tested (after a green run)
"""

from __future__ import annotations

import re
import sys
from importlib.metadata import PackageNotFoundError, requires, version
from pathlib import Path

TESTED = Path(__file__).with_name("tested-versions.txt")


def direct_dependencies() -> list[str]:
    """Names of robocfg's requirements, the test and dev extras included."""
    names = set()
    for req in requires("robocfg") or []:
        names.add(re.split(r"[ ;<>=!~\[]", req, maxsplit=1)[0].lower())
    return sorted(names)


def resolved() -> dict[str, str]:
    out = {}
    for name in direct_dependencies():
        try:
            out[name] = version(name)
        except PackageNotFoundError:
            continue  # an extra that is not installed here
    return out


def main() -> int:
    now = resolved()
    if "--write" in sys.argv:
        TESTED.write_text("".join(f"{k}=={v}\n" for k, v in now.items()))
        print(f"wrote {TESTED} ({len(now)} packages)")
        return 0
    tested = dict(line.strip().split("==") for line in TESTED.read_text().splitlines() if "==" in line)
    drift = [f"{k} {tested[k]} -> {v}" for k, v in now.items() if k in tested and tested[k] != v]
    new = [f"{k} {v}" for k, v in now.items() if k not in tested]
    print("resolved:", ", ".join(f"{k} {v}" for k, v in now.items()))
    print("drift since the tested set:", "; ".join(drift) or "none")
    if new:
        print("not in the tested set:", "; ".join(new))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
