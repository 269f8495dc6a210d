"""Every figure of the course can be read by every student (WCAG 2.1 AA, colour-blind readers).

The course's colours and line styles (`coursekit.style`), the checks of `figure_checks` (palette
colours, curves told apart by line style or marker and not by colour alone, text contrast of
4.5:1) shown to catch a figure made the old way, then applied to every figure the course makes:
each plotting helper and every explorer (here), and every figure and explorer the chapter
notebooks show (inside the kernel that runs each notebook, `notebook_figures`; the notebooks
executed once per test session, tests/executed_chapters.py), where the layout
is checked too, as JupyterLab shows the figure and as the website draws it for its column. Last,
the explorer's own text colours (its CSS) against JupyterLab's light and dark themes.
"""

import re
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import pytest  # noqa: E402
from matplotlib.colors import to_hex  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

import coursekit as ck  # noqa: E402
from coursekit.tools.notebooks import chapter_notebooks  # noqa: E402
from figure_checks import colour_problems, contrast_problems, curve_problems, style_problems  # noqa: E402
from notebook_figures import figure_reports  # noqa: E402
from test_figure_layout import EXPLORERS, FIGURES, settings, undrawn  # noqa: E402

NOTEBOOKS = chapter_notebooks(Path(__file__).resolve().parents[1] / "notebooks")

#: Okabe and Ito's palette ("Color Universal Design", 2008), as published
OKABE_ITO = {"#000000", "#e69f00", "#56b4e9", "#009e73", "#f0e442", "#0072b2", "#d55e00", "#cc79a7"}


# --- the style ------------------------------------------------------------------------------

def test_contrast_ratio_is_wcag_s():
    assert ck.contrast_ratio("black", "white") == pytest.approx(21.0)
    assert ck.contrast_ratio("white", "black") == pytest.approx(21.0)
    assert ck.contrast_ratio("#767676") == pytest.approx(4.54, abs=0.005)      # the lightest AA grey
    assert ck.contrast_ratio("#777777") == pytest.approx(4.48, abs=0.005)
    assert ck.contrast_ratio("#0072B2", "#0072B2") == pytest.approx(1.0)
    # translucent black text is a grey; a translucent background is painted over the white page
    assert ck.contrast_ratio((0, 0, 0, 0.5)) == pytest.approx(ck.contrast_ratio((0.5, 0.5, 0.5)))
    assert ck.contrast_ratio("black", (0, 0, 0, 0.0)) == pytest.approx(21.0)


def test_palette_is_okabe_ito_s_and_stands_out_against_white():
    palette = {to_hex(c) for c in ck.PALETTE.values()}
    assert palette <= OKABE_ITO and len(palette) == 5
    if "okabe_ito" in matplotlib.color_sequences:        # matplotlib 3.10 and later carry it too
        assert palette <= {to_hex(c) for c in matplotlib.color_sequences["okabe_ito"]}
    assert all(ck.contrast_ratio(c) >= 3.0 for c in palette)      # WCAG 1.4.11, lines and marks


def test_curve_styles_never_differ_by_colour_alone():
    looks = [(s["linestyle"], s.get("marker")) for s in (ck.curve_style(k, marker=True) for k in range(20))]
    assert len(set(looks)) == 20
    plain = [ck.curve_style(k) for k in range(4)]
    assert len({s["linestyle"] for s in plain}) == 4 and len({s["color"] for s in plain}) == 4
    assert ck.curve_style(4) == ck.curve_style(0)
    with pytest.raises(ValueError, match="k must be"):
        ck.curve_style(-1)


def test_text_colour_darkens_just_enough():
    for colour in ck.PALETTE.values():
        dark = ck.text_colour(colour)
        assert 4.5 <= ck.contrast_ratio(dark) < 4.7 or dark == to_hex(colour)
    assert ck.text_colour("#0072B2") == "#0072b2"                    # 5.2:1 already
    with pytest.raises(ValueError, match="background must leave room"):
        ck.text_colour("C0", background="#444444")


def test_course_figures_and_plt_style_use_take_the_course_curve_styles():
    fig, ax = ck.new_figure()
    drawn = [ax.plot([0, 1])[0] for _ in range(4)]
    assert [(to_hex(line.get_color()), line.get_linestyle()) for line in drawn] == \
        [(to_hex(s["color"]), s["linestyle"]) for s in ck.CURVE_STYLES]
    axes = ck.course_subplots(Figure(), 1, 2)
    assert [to_hex(a.plot([0, 1])[0].get_color()) for a in axes] == [to_hex(ck.PALETTE["blue"])] * 2
    with plt.style.context(ck.COURSE_STYLE):
        assert plt.rcParams["axes.prop_cycle"] == ck.COURSE_STYLE["axes.prop_cycle"]
    with pytest.raises(ValueError, match="fig must be a matplotlib Figure"):
        ck.course_subplots(ax)


# --- the checks catch a figure made the old way ---------------------------------------------

def test_the_checks_catch_colour_alone_off_palette_colours_and_faint_text():
    fig = Figure()
    ax = fig.subplots()
    ax.plot([0, 1], [0, 1], color="C0", label="first")              # matplotlib's default colours
    ax.plot([0, 1], [1, 0], color="C1", label="second")             # the same solid line
    ax.axhline(0.5, color="0.5")                                    # a reference line: no problem
    ax.annotate("t = 0", xy=(0, 0), color="0.65")                   # grey text, 2.5:1
    ax.legend(facecolor="0.3", framealpha=1.0)                      # black text on a dark frame
    fig.suptitle("a title", color="#CC79A7")                        # a palette colour is no text colour
    assert len(colour_problems(fig)) == 2
    assert curve_problems(fig) == ["'first' and 'second' of axes 0 differ by colour alone "
                                   "(both line style '-', marker 'None')"]
    faint = contrast_problems(fig)
    assert len(faint) == 4 and all("contrast" in p for p in faint), faint     # annotation, 2 legend texts, title
    assert any("'t = 0'" in p for p in faint) and any("'a title'" in p for p in faint)


def test_an_explorer_s_draw_with_plain_subplots_gets_the_course_style():
    from coursekit.explorers import Explorer, slider

    def draw(fig):
        ax = fig.subplots()
        return [ax.plot([0, 1], [0, k], label=f"curve {k}")[0] for k in (1, 2)]
    e = Explorer(title="two curves", controls=dict(a=slider(1.0, 0.0, 2.0, 0.1, "a [-]")),
                 compute=lambda a: a, draw=draw, update=lambda h, r: None)
    e.fig.axes[0].legend()
    assert style_problems(e.fig) == []
    assert [to_hex(line.get_color()) for line in e.handles] == [to_hex(s["color"]) for s in ck.CURVE_STYLES[:2]]


def test_the_same_figure_in_the_course_style_passes():
    fig, ax = ck.new_figure()
    ax.plot([0, 1], [0, 1], label="first")
    ax.plot([0, 1], [1, 0], label="second")
    ax.axhline(0.5, color="0.5")
    ax.annotate("t = 0", xy=(0, 0), color=ck.text_colour(ck.PALETTE["vermillion"]))
    ax.legend()
    fig.suptitle("a title")
    assert style_problems(fig) == []


# --- every figure of the course ----------------------------------------------------------

@pytest.mark.parametrize("name", FIGURES)
def test_plotting_helper_figure_is_readable_by_everyone(name):
    assert style_problems(FIGURES[name]()) == []


@pytest.mark.parametrize("name", EXPLORERS)
def test_explorer_figure_is_readable_by_everyone_over_its_slider_range(name):
    explorer = undrawn(EXPLORERS[name]())     # style_problems draws the figure itself
    found = []
    for setting in settings(explorer.controls, every_end=False):
        for control, value in setting.items():
            explorer.controls[control].value = value
        explorer.refresh()
        found += [f"{setting}: {p}" for p in style_problems(explorer.fig)]
    assert not found, "\n".join(found)


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_every_figure_a_notebook_shows_is_readable_by_everyone(path, executed_chapters):
    reports = figure_reports(executed_chapters.instructor(path.name))
    assert reports, "the notebook shows no figure: every chapter has explorers and figures"
    missing = [r["cell"] for r in reports if r["report"] is None]
    assert not missing, f"images of cells {missing} were not checked (not a figure or explorer?)"
    found = [f"cell {r['cell']}, {kind}: {problem}" for r in reports
             for kind, problems in r["report"].items() for problem in problems]
    assert not found, "\n".join(found)


# --- the explorer's own text (its CSS) ------------------------------------------------------

def _themes() -> dict:
    """{name: CSS} of JupyterLab's light and dark themes, as installed."""
    from jupyter_core.paths import jupyter_path
    found = {}
    for folder in map(Path, jupyter_path("lab", "themes", "@jupyterlab")):
        for name in ("light", "dark"):
            css = folder / f"theme-{name}-extension" / "index.css"
            if css.is_file():
                found.setdefault(name, css.read_text(encoding="utf-8"))
    return found


def _lab_variables() -> str:
    """The CSS variables JupyterLab defines outside its themes' files: JupyterLab 4.0 keeps its
    material palette (``--md-red-700``, ...) in its static bundle, which its themes refer to."""
    from jupyter_core.paths import jupyter_path
    return "".join(path.read_text(encoding="utf-8", errors="ignore")
                   for folder in map(Path, jupyter_path("lab", "static")) for path in folder.glob("jlab_core*.js"))


def _resolve(value: str, css: str) -> str:
    """A CSS colour value with its var(--name, fallback) resolved by the theme's `css`."""
    while (match := re.fullmatch(r"var\((--[\w-]+)\s*(?:,\s*(.+))?\)", value.strip())):
        defined = re.search(rf"{match.group(1)}:\s*([^;]+);", css)
        value = defined.group(1) if defined else match.group(2)
    value = value.strip()
    return value if not re.fullmatch(r"#[0-9a-fA-F]{3}", value) else "#" + "".join(2 * c for c in value[1:])


def test_explorer_text_colours_keep_4_5_to_1_in_jupyterlab_s_themes_and_elsewhere():
    from coursekit.explorers._view import VIEW_CSS
    colours = re.findall(r"(?<![-\w])color:\s*([^;}]+)", VIEW_CSS.read_text(encoding="utf-8"))
    assert colours, "the explorer's CSS sets no text colour: nothing to check"
    themes, lab = _themes(), _lab_variables()
    assert set(themes) == {"light", "dark"}, "JupyterLab's themes are not installed (the lab extra)"
    for value in colours:
        assert ck.contrast_ratio(_resolve(value, "")) >= 4.5, f"{value} on a white page without JupyterLab"
        for name, css in themes.items():
            background = _resolve("var(--jp-layout-color0)", css)
            ratio = ck.contrast_ratio(_resolve(value, css + lab), background)
            assert ratio >= 4.5, f"{value} on {background} in JupyterLab's {name} theme: {ratio:.2f}:1"
