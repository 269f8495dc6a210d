"""The default settings coursekit gives JupyterLab and Notebook 7 where it is installed.

A notebook saved after Run All keeps its explorers only when the front end saves the widget
state in it (the widget manager's ``saveState``, off by default): reopened without it, every
explorer said "Error displaying widget: model not found". coursekit installs
``share/jupyter/lab/settings/overrides.d/coursekit.json``, a package's own file of default
settings beside the user's ``overrides.json``, which turns it on; the browser test
(`tests/test_browser.py`) saves, closes and reopens a notebook with these settings.
"""

import json
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SETTINGS = ROOT / "jupyter-config" / "coursekit.json"
TARGET = "share/jupyter/lab/settings/overrides.d"


def _widget_manager_schema() -> tuple[str, dict]:
    """(plugin id, settings schema) of the widget manager's labextension, as installed."""
    folder = Path(sys.prefix) / "share/jupyter/labextensions/@jupyter-widgets/jupyterlab-manager/schemas"
    path = next(folder.glob("*/*/plugin.json"))
    package = json.loads((path.parent / "package.json.orig").read_text(encoding="utf-8"))["name"]
    return f"{package}:{path.stem}", json.loads(path.read_text(encoding="utf-8"))


def test_the_install_puts_the_course_settings_where_jupyterlab_reads_package_defaults():
    # the [tool.setuptools] table's data-files line (tomllib is Python 3.11+; the course runs on 3.10)
    table = re.search(r"^\[tool\.setuptools\]\n(.*?)^\[", (ROOT / "pyproject.toml").read_text(encoding="utf-8"),
                      re.M | re.S)
    assert table, "pyproject.toml has no [tool.setuptools] table"
    line = re.search(r"^data-files = (\{.*\})$", table.group(1), re.M)
    assert line and json.loads(line.group(1).replace(" = ", ": ")) == {TARGET: [str(SETTINGS.relative_to(ROOT))]}


def test_the_course_settings_save_the_widget_state_in_the_notebook():
    plugin, schema = _widget_manager_schema()
    settings = json.loads(SETTINGS.read_text(encoding="utf-8"))
    assert settings == {plugin: {"saveState": True}}
    assert schema["properties"]["saveState"]["type"] == "boolean"
