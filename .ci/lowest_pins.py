"""Print pip requirements that pin every declared dependency to its lower bound.

CI's oldest run installs coursekit with these pins (``pip install -e ".[dev]" -r FILE``),
so the versions it proves are read from pyproject.toml and never drift from it. Every
dependency of the package and of the extras named on the command line must have the form
``name>=X`` (optionally with ``,<Y``); anything else stops CI with a message. An extra
that names the project itself (``coursekit[lab]``) brings in that extra's pins.

Usage: python .ci/lowest_pins.py [pyproject.toml] [extra ...]   (Python >= 3.11: tomllib)
"""

import re
import sys
import tomllib

_SELF = re.compile(r"^\s*([A-Za-z0-9_.\-]+)\[([^\]]*)\]\s*$")  # e.g. coursekit[lab]
_LOWER = re.compile(r"^\s*([A-Za-z0-9_.\-]+)(\[[^\]]*\])?\s*>=\s*([0-9][0-9A-Za-z.]*)\s*(,\s*<[^;]*)?$")


def lowest_pins(pyproject: dict, extras: list[str]) -> list[str]:
    project = pyproject["project"]
    requirements = list(project["dependencies"])
    extras = list(extras)
    for extra in extras:  # grows while self-references such as "coursekit[lab]" are met
        for requirement in project["optional-dependencies"][extra]:
            own = _SELF.match(requirement)
            if own is not None and own.group(1).lower() == project["name"].lower():
                extras += [e.strip() for e in own.group(2).split(",") if e.strip() not in extras]
            else:
                requirements.append(requirement)
    pins = []
    for requirement in requirements:
        match = _LOWER.match(requirement)
        if match is None:
            raise SystemExit(f"lowest_pins: cannot pin {requirement!r}: expected the form 'name>=X'")
        pins.append(f"{match.group(1)}=={match.group(3)}")
    return pins


def main(argv: list[str]) -> None:
    path = argv[0] if argv else "pyproject.toml"
    with open(path, "rb") as file:
        pyproject = tomllib.load(file)
    print("\n".join(lowest_pins(pyproject, argv[1:])))


if __name__ == "__main__":
    main(sys.argv[1:])
