"""The website's figures drawn for its column (coursekit.tools.site_figures), without a browser.

The sizes: a figure wider than the column is drawn z times larger on the same pixels, z just
enough for its smallest text to come out at `MIN_TEXT_PX` once the browser fits it to the
column; a narrow figure is left alone; the figure is given back as it was. The display: a
display formatter set up as the site's kernel sets it up (`install`, then the inline backend's
own registration, as ``%matplotlib inline`` makes it), checked on a figure and an explorer.
tests/test_site_browser.py measures the result in Chromium.
"""

import base64
import io
from types import SimpleNamespace

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402
from IPython.core.formatters import DisplayFormatter  # noqa: E402
from IPython.core.pylabtools import select_figure_formats  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from PIL import Image  # noqa: E402

from coursekit.explorers import ch1  # noqa: E402
from coursekit.tools import site, site_figures  # noqa: E402
from coursekit.tools.notebooks import ALT  # noqa: E402
from coursekit.tools.site_figures import COLUMN_PX, MIN_TEXT_PX, column_zoom, drawn_for_the_column  # noqa: E402

SMALL = 10 * 0.833       # matplotlib's "small" font size at its default 10 points


def _figure(width: float) -> Figure:
    fig = Figure(figsize=(width, 4), dpi=100)
    ax = fig.subplots()
    ax.plot(np.linspace(0, 1, 20), np.linspace(0, 1, 20) ** 2, label="x1")
    ax.set(xlabel="time t [s]", ylabel="x1 [m]", title="a figure")
    ax.legend(fontsize="small")
    return fig


def test_a_wide_figure_is_drawn_larger_on_the_same_pixels_just_enough():
    fig = _figure(13.0)
    assert site_figures.smallest_text_pt(fig) == pytest.approx(SMALL, abs=0.01)
    zoom = column_zoom(fig)
    # at 1,300 px the column shows it at 688/1300: the small text needs z = 11.5 / (8.33 pt at 100 dpi * 0.53)
    assert zoom == pytest.approx(MIN_TEXT_PX / (SMALL / 72 * 100 * COLUMN_PX / 1300), rel=1e-3)
    with drawn_for_the_column(fig) as inside:
        assert inside == zoom
        assert fig.get_size_inches() * fig.dpi == pytest.approx([1300, 400])
        assert fig.dpi == pytest.approx(100 * zoom)
    assert tuple(fig.get_size_inches()) == (13.0, 4.0) and fig.dpi == 100


def test_a_figure_that_fits_the_column_is_left_alone():
    assert column_zoom(_figure(6.4)) == 1.0                   # 640 px, small text at 11.6 px
    assert column_zoom(Figure(figsize=(13, 4))) == 1.0        # no text at all
    assert site_figures.smallest_text_pt(Figure()) is None


def _formatter():
    """A display formatter set up as the site's kernel: `install`, then %matplotlib inline."""
    shell = SimpleNamespace(display_formatter=DisplayFormatter())
    site_figures.install(shell)
    select_figure_formats(shell, {"png"}, bbox_inches=None)
    return shell.display_formatter


def _png(data) -> Image.Image:
    return Image.open(io.BytesIO(base64.b64decode(data) if isinstance(data, str) else data))


def test_the_site_kernel_gives_a_figure_its_png_for_the_column_description_and_smallest_text():
    fig = _figure(13.0)
    data, _ = _formatter().format(fig)
    png = _png(data["image/png"])
    assert png.size == (1300, 400)
    assert png.info["dpi"][0] == pytest.approx(100 * column_zoom(fig), rel=1e-3)
    assert float(data[site.SMALLEST_TEXT]) == pytest.approx(SMALL, abs=0.01)
    assert data[ALT].startswith("The plot (a figure) shows x1 [m] against time t [s]")
    assert tuple(fig.get_size_inches()) == (13.0, 4.0) and fig.dpi == 100


def test_the_site_kernel_draws_an_explorer_for_the_column_too():
    explorer = ch1.msd_explorer()                               # 11 x 4.5 inches
    zoom = column_zoom(explorer.fig, explorer.natural_dpi)
    assert zoom > 1.2
    data, _ = _formatter().format(explorer)
    png = _png(data["image/png"])
    assert png.size == (1100, 450) and png.info["dpi"][0] == pytest.approx(100 * zoom, rel=1e-3)
    assert float(data[site.SMALLEST_TEXT]) == pytest.approx(SMALL, abs=0.01)
    assert ALT not in data and "Mass-spring-damper" in data["text/plain"]     # its own description
    assert explorer.png == explorer.static_png()               # and it is its natural self again
