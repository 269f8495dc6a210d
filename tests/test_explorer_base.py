"""Explorer's static fallback (PNG next to the widget view) and lecture mode."""

import base64
import re

import matplotlib as mpl
import numpy as np
import pytest

import coursekit as ck
from coursekit.explorers import Explorer, dropdown, int_slider, slider
from coursekit.tools.kernel_metadata import kernelspec_metadata

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def _compute(a):
    t = np.linspace(0.0, 5.0, 200)
    return t, np.exp(-a * t) * np.cos(3.0 * t)


def _draw(fig):
    ax = fig.subplots()
    line, = ax.plot([], [], label="y")
    ax.set(title="demo", xlabel="t [s]", ylabel="y [m]")
    return ax, line


def _update(handles, result):
    ax, line = handles
    line.set_data(*result)
    ax.relim()
    ax.autoscale_view()


def _explorer(a=1.0):
    return Explorer(title="Demo", controls={"a": slider(a, 0.1, 3.0, 0.1, "a")},
                    compute=_compute, draw=_draw, update=_update)


@pytest.fixture(autouse=True)
def _lecture_mode_off():
    yield
    ck.lecture_mode(False)


def _png_size(png: bytes) -> tuple[int, int]:
    # width and height are the first two big-endian ints of the IHDR chunk
    return int.from_bytes(png[16:20], "big"), int.from_bytes(png[20:24], "big")


def test_mimebundle_holds_the_widget_view_and_a_static_png():
    exp = _explorer()
    bundle = exp._repr_mimebundle_()
    assert "application/vnd.jupyter.widget-view+json" in bundle
    assert bundle["application/vnd.jupyter.widget-view+json"]["model_id"] == exp.widget.model_id
    png = base64.b64decode(bundle["image/png"])
    assert png.startswith(PNG_MAGIC)
    assert bundle["text/plain"].startswith("Demo. Settings: a = 1. The plot (demo) shows y [m] against t [s]")
    assert "y: starts at 1," in bundle["text/plain"]          # described from its data


def test_moving_a_slider_refreshes_the_png_and_the_image_widget():
    exp = _explorer()
    widget = exp.widget
    before = exp.png
    exp.controls["a"].value = 2.5          # what each move of a dragged slider does
    assert exp.params == {"a": 2.5}
    assert exp.png != before
    assert widget.children[-1].png == exp.png
    np.testing.assert_allclose(exp.handles[1].get_ydata(), _compute(2.5)[1])
    assert base64.b64decode(exp._repr_mimebundle_()["image/png"]) == exp.png


def test_lecture_mode_enlarges_explorer_figures_and_off_restores_defaults():
    default = _png_size(_explorer().png)
    before = {key: mpl.rcParams[key] for key in ck.LECTURE_STYLE}
    ck.lecture_mode()
    assert ck.is_lecture_mode()
    exp = _explorer()
    assert tuple(exp.fig.get_size_inches()) == pytest.approx(ck.LECTURE_STYLE["figure.figsize"])
    big = _png_size(exp.png)
    assert big[0] > default[0] and big[1] > default[1]
    fig, ax = ck.new_figure()
    line, = ax.plot([0, 1], [0, 1])
    assert line.get_linewidth() == ck.LECTURE_STYLE["lines.linewidth"]
    assert ax.title.get_fontsize() == ck.LECTURE_STYLE["axes.titlesize"]
    ck.lecture_mode()                       # switching on twice keeps the original defaults
    ck.lecture_mode(False)
    assert not ck.is_lecture_mode()
    assert {key: mpl.rcParams[key] for key in ck.LECTURE_STYLE} == before
    assert _png_size(_explorer().png) == default


def test_lecture_mode_off_without_on_changes_nothing():
    before = dict(mpl.rcParams)
    ck.lecture_mode(False)
    assert dict(mpl.rcParams) == before


def test_lecture_mode_rejects_a_non_bool():
    with pytest.raises(ValueError, match="on must be True or False"):
        ck.lecture_mode("yes")


@pytest.fixture(scope="module")
def executed_demo():
    """A notebook with one explorer, executed once in a real kernel."""
    nbformat = pytest.importorskip("nbformat")
    pytest.importorskip("nbclient")
    from nbclient import NotebookClient
    nb = nbformat.v4.new_notebook()
    nb.metadata["kernelspec"] = kernelspec_metadata()
    nb.cells = [nbformat.v4.new_code_cell(
        "import numpy as np\nfrom coursekit.explorers import Explorer, dropdown, int_slider, slider\n"
        "Explorer(title='Demo', controls={'a': slider(1.0, 0.1, 3.0, 0.1, 'a')},\n"
        "         compute=lambda a: np.exp(-a * np.linspace(0, 5, 50)),\n"
        "         draw=lambda fig: fig.subplots().plot([], [])[0],\n"
        "         update=lambda line, y: line.set_data(np.arange(y.size), y))")]
    NotebookClient(nb, timeout=120, kernel_name="python3").execute()
    return nb


def test_executed_notebook_output_carries_the_png_for_github_and_nbviewer(executed_demo):
    fallback, shown = executed_demo.cells[0].outputs     # the figure for a reopened notebook first
    assert fallback["metadata"] == {"coursekit_explorer_fallback": True}
    assert 'class="ck-explorer-fallback"' in fallback["data"]["text/html"]
    data = shown["data"]
    assert "application/vnd.jupyter.widget-view+json" in data
    assert base64.b64decode(data["image/png"]).startswith(PNG_MAGIC)


def test_html_export_shows_the_png_without_a_widget_state(executed_demo):
    import copy

    from nbconvert import HTMLExporter
    nb = copy.deepcopy(executed_demo)
    nb.metadata.pop("widgets", None)
    html, _ = HTMLExporter().from_notebook_node(nb)
    assert re.search(r'<img[^>]+src="data:image/png;base64,', html)
    assert "VBox(" not in html


def test_html_export_with_widget_state_stores_the_figure_view(executed_demo):
    from nbconvert import HTMLExporter
    html, _ = HTMLExporter().from_notebook_node(executed_demo)
    state = executed_demo.metadata["widgets"]["application/vnd.jupyter.widget-state+json"]["state"]
    images = [m for m in state.values() if m["model_name"] == "AnyModel"]
    # the figure view's stored state holds the PNG
    assert len(images) == 1 and images[0]["buffers"][0]["path"] == ["png"]
    assert base64.b64decode(images[0]["buffers"][0]["data"]).startswith(PNG_MAGIC)
    assert "application/vnd.jupyter.widget-view+json" in html and "VBox(" not in html


def _readout_explorer():
    def compute(a):
        if a > 2.5:
            raise ZeroDivisionError("no response above a = 2.5")
        return _compute(a)
    return Explorer(title="Demo", controls={"a": slider(1.0, 0.1, 3.0, 0.1, "a [1/s]")}, compute=compute,
                    draw=_draw, update=_update, readout=lambda r: f"peak {r[1].max():.3g} m\nsecond line")


def test_the_readout_shows_the_numbers_and_joins_the_text_alternative():
    exp = _readout_explorer()
    widget = exp.widget
    assert exp.text == "peak 1 m\nsecond line"
    assert exp.alt == "Demo. Settings: a = 1. peak 1 m; second line"
    readout = widget.children[2]
    assert "peak 1 m<br>second line" in readout.value
    assert widget.children[-1].alt == exp.alt


def test_a_compute_that_fails_for_a_setting_keeps_the_figure_and_says_why():
    exp = _readout_explorer()
    widget = exp.widget
    shown = exp.png
    exp.controls["a"].value = 2.8                    # no exception reaches the widget callback
    assert exp.png == shown and exp.error.startswith("ZeroDivisionError: no response above")
    assert "ck-error" in widget.children[2].value and "No figure for these settings" in exp.alt
    exp.controls["a"].value = 2.0
    assert exp.error is None and exp.png != shown and "ck-error" not in widget.children[2].value


def test_a_compute_that_fails_for_the_first_settings_is_named():
    with pytest.raises(ValueError, match=r"could not show its first settings \{'a': 1.0\}: KeyError"):
        Explorer(title="Broken", controls={"a": slider(1.0, 0.1, 3.0, 0.1, "a")},
                 compute=lambda a: {}["missing"], draw=_draw, update=_update)


@pytest.mark.parametrize("call, match", [
    (lambda: slider(float("nan"), 0, 1, 0.1, "a"), "value contains NaN"),
    (lambda: slider(0.5, 0, 1, 0.0, "a"), "step must be positive"),
    (lambda: slider(0.5, 0, 1, -0.1, "a"), "step must be positive"),
    (lambda: slider(0.5, 0, float("inf"), 0.1, "a"), "max contains"),
    (lambda: slider(0.5, 1, 0, 0.1, "a"), "min must be below max"),
    (lambda: slider(2.0, 0, 1, 0.1, "a"), r"value must lie in \[min, max\]"),
    (lambda: slider(0.5, 0, 1, 0.1, ""), "description must be a non-empty string"),
    (lambda: int_slider(1, 0, 5, "n", step=0.5), "whole numbers"),
    (lambda: dropdown([], None, "system"), "options must be a non-empty list"),
    (lambda: dropdown(["a", "b"], "c", "system"), "value must be one of the options"),
    (lambda: Explorer(title="x", controls={}, compute=_compute, draw=_draw, update=_update),
     "controls must be a non-empty dict"),
])
def test_malformed_controls_are_refused_naming_the_argument(call, match):
    with pytest.raises(ValueError, match=match):
        call()


@pytest.mark.parametrize("kwargs, match", [
    (dict(controls={"a": 1.0}), r"controls\['a'\] must be a control"),
    (dict(compute="not callable"), "compute must be a function"),
    (dict(readout=3), "readout must be a function"),
    (dict(title=None), "title must be a string"),
])
def test_explorer_arguments_of_the_wrong_type_are_refused(kwargs, match):
    args = dict(title="x", controls={"a": slider(1.0, 0.1, 3.0, 0.1, "a")}, compute=_compute, draw=_draw,
                update=_update)
    with pytest.raises(TypeError, match=match):
        Explorer(**{**args, **kwargs})


def test_rescale_fits_the_view_to_data_moved_by_an_update():
    from matplotlib.figure import Figure
    from coursekit.explorers import rescale
    ax = Figure().subplots()
    (line,) = ax.plot([0, 1], [0, 1])
    line.set_data([0, 10], [-5, 50])
    rescale(ax)
    lo, hi = ax.get_ylim()
    assert lo <= -5 and hi >= 50
    rescale(ax, axis="x")
    assert ax.get_xlim()[1] >= 10


def test_the_widget_s_script_and_style_sheet_are_files_declared_as_package_data():
    """anywidget reads them from the package's folder: a wheel without them shows no figure."""
    import ast
    import fnmatch
    from pathlib import Path

    from coursekit.explorers import _view
    root = Path(_view.__file__).resolve().parents[2]
    pyproject = (root / "pyproject.toml").read_text(encoding="utf-8")
    section = pyproject.split("[tool.setuptools.package-data]", 1)[1].split("\n[", 1)[0]
    declared = re.search(r'^"coursekit\.explorers"\s*=\s*(\[.*?\])', section, re.M)
    assert declared, "pyproject.toml declares no package data for coursekit.explorers"
    patterns = ast.literal_eval(declared.group(1))
    view = _view.FigureView()
    for path, shipped in ((_view.VIEW_JS, view._esm), (_view.VIEW_CSS, view._css)):
        assert path.parent == Path(_view.__file__).parent and path.stat().st_size > 0
        assert any(fnmatch.fnmatch(path.name, p) for p in patterns), (path.name, patterns)
        assert str(shipped) == path.read_text(encoding="utf-8")
    assert "export default" in str(view._esm) and ".ck-explorer" in str(view._css)
