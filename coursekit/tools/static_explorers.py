"""Explorers without a kernel: live sliders on the course website and in the slides.

At build time the kernel that executes a notebook for the website or the slides renders each
explorer's figure for a set of its settings, with the explorer's own ``compute``/``update`` and
frame renderer (the code JupyterLab runs, `coursekit.explorers`; an explorer written as
docs/extending.md shows gets this with nothing more), and adds the frames to the explorer's
display data under `MIME` (`install`). The build then writes the frames as WebP files beside
the pages and puts in the explorer's place a small block of HTML (`publish`): the title, one
native, labelled ``<input type="range">`` per slider (a ``<select>`` per dropdown), a line
saying which settings are live, the readout, the figure and a polite live region. A script of
the project's own (``templates/static_explorers/explorers.js``: no framework, no request but
the frames) shows the frame of the settings the inputs stand at as they move.

Which settings are stored (`plan`): every choice of each dropdown; for the sliders either every
combination of their stored values (the full grid), when at least `FULL_GRID_MIN` values of each
fit in the frames allowed, or one slider at a time with the others at their defaults (the star).
A slider keeps the values that fit (`slider_values`: its default, values a whole number of its
steps apart, and both ends of its range). The range inputs step through exactly these values,
and on the star a slider moved while another stands away from its default brings that one back
to it: every state a reader can reach shows the figure computed for exactly those settings.

The frame of settings S is what the explorer draws after one move from its defaults to S, at
rest, as in JupyterLab: the view limits it had for its defaults, then its update for S (and,
when ``compute`` fails for S, the figure of the defaults with the readout saying why), laid out
for S from where the defaults' layout put the axes (`render_laid_out`), so that no frame depends
on the frames drawn before it. Frames whose layout would come out the same (the same text and
limits, only curves and markers inside the axes changed) are drawn one after the other, the first
laid out and the others blitted over its background in its layout (`_render`): the same pixels
for about a tenth of a full draw.
The frames are lossless (WebP through Pillow), at most `FRAME_BUDGET` bytes per explorer
(fewer values per slider when they would be more) and `SITE_BUDGET` for a whole build.
"""

from __future__ import annotations

import base64
import contextlib
import hashlib
import html
import io
import itertools
import json
import math
import shutil
from pathlib import Path

import numpy as np

__all__ = ["MIME", "MAX_FRAMES", "FULL_GRID_MIN", "FRAME_BUDGET", "SITE_BUDGET", "ASSETS", "ASSET_FILES",
           "slider_values", "plan", "render_laid_out", "render_frames", "explorer_data", "install",
           "explorer_html", "publish", "copy_assets", "check_site_budget"]

#: the media type under which the kernel adds an explorer's frames to its display data
MIME = "application/x-coursekit-static-explorer+json"
#: at most this many frames per explorer (the build time: about 0.2 s of a core each)
MAX_FRAMES = 48
#: the full grid is stored when each slider keeps at least this many values (or all it has)
FULL_GRID_MIN = 7
#: bytes of frames per explorer, and for everything one build of the site or the slides writes
FRAME_BUDGET, SITE_BUDGET = 3_000_000, 30_000_000
#: the folder (beside the pages) that holds the frames, the script and its style sheet
ASSETS = "ck-explorers"
#: the script and the style sheet, shipped with the package
ASSET_FILES = ("explorers.js", "explorers.css")
_TEMPLATES = Path(__file__).resolve().parent / "templates" / "static_explorers"


def slider_values(widget, count: int) -> list:
    """At most `count` (>= 2) values of the slider `widget` to store: its default, the values a
    whole number k of its steps away from it (the smallest k that fits), and both ends of its
    range; each one a value the slider can hold (a whole number of steps from its minimum)."""
    if not isinstance(count, int) or count < 2:
        raise ValueError(f"count must be a whole number >= 2: received {count!r}.")
    low, high, step, default = widget.min, widget.max, widget.step, widget.value
    whole = isinstance(default, int) and not isinstance(default, bool)
    steps = int(round((high - low) / step))
    for k in range(1, steps + 2):
        below, above = int((default - low) / (k * step) + 1e-9), int((high - default) / (k * step) + 1e-9)
        values = [default + j * k * step for j in range(-below, above + 1)]
        values = sorted({*values, low, high})
        if len(values) <= count:
            break
    values = [default if abs(v - default) < 1e-9 * step else round(v, 10) for v in values]
    return [int(round(v)) for v in values] if whole else [float(v) for v in values]


def _describe_controls(explorer, count: int) -> list[dict]:
    """One entry per control: name, label, kind ("range" or "select"), values, texts, default."""
    import ipywidgets as widgets
    out = []
    for name, w in explorer.controls.items():
        if isinstance(w, (widgets.FloatSlider, widgets.IntSlider)):
            values = slider_values(w, count)
            fmt = getattr(w, "readout_format", "d") if isinstance(w, widgets.FloatSlider) else "d"
            texts = [format(v, fmt) for v in values]
            out.append(dict(name=name, label=w.description, kind="range", values=values, texts=texts,
                            default=values.index(w.value)))
        elif isinstance(w, widgets.Dropdown):
            pairs = [o if isinstance(o, tuple) else (str(o), o) for o in w.options]
            values = [value for _, value in pairs]
            out.append(dict(name=name, label=w.description, kind="select", values=values,
                            texts=[str(label) for label, _ in pairs], default=values.index(w.value)))
        else:
            raise TypeError(f"the control {name!r} of the explorer {explorer.title!r} is a "
                            f"{type(w).__name__}: a static page shows sliders and dropdowns only")
    return out


def _natural_counts(explorer) -> list[int]:
    import ipywidgets as widgets
    return [int(round((w.max - w.min) / w.step)) + 1 if isinstance(w, (widgets.FloatSlider, widgets.IntSlider))
            else len(w.options) for w in explorer.controls.values()]


def plan(explorer, max_frames: int = MAX_FRAMES) -> dict:
    """The settings to store for `explorer`, at most about `max_frames` of them (every dropdown
    choice counts in full): ``{"controls": [...], "states": [tuple of value indices], "full": bool}``
    (`_describe_controls` gives each control's values; a state holds one index per control)."""
    if not isinstance(max_frames, int) or max_frames < 1:
        raise ValueError(f"max_frames must be a whole number >= 1: received {max_frames!r}.")
    counts = _natural_counts(explorer)
    kinds = ["select" if not hasattr(w, "step") else "range" for w in explorer.controls.values()]
    choices = math.prod(n for n, kind in zip(counts, kinds) if kind == "select")
    sliders = sum(kind == "range" for kind in kinds)
    budget = max(1, max_frames // choices)
    each = int(math.floor(budget ** (1 / sliders) + 1e-9)) if sliders else 1
    full = sliders <= 1 or all(min(n, each) >= min(n, FULL_GRID_MIN) for n, kind in zip(counts, kinds)
                                if kind == "range")
    if not full:
        each = 1 + (budget - 1) // sliders
    controls = _describe_controls(explorer, max(2, each))
    axes = [range(len(c["values"])) for c in controls]
    defaults = [c["default"] for c in controls]
    states = []
    for state in itertools.product(*axes):
        away = [j for j, c in enumerate(controls) if c["kind"] == "range" and state[j] != defaults[j]]
        if full or len(away) <= 1:
            states.append(tuple(state))
    return dict(controls=controls, states=states, full=full)


def _settings(controls: list[dict], state) -> dict:
    return {c["name"]: c["values"][i] for c, i in zip(controls, state)}


def _view(fig) -> list:
    """Each axes' limits, autoscale switches and place, to put back with `_restore` (the layout of
    a figure with an equal aspect starts from where its axes stand)."""
    return [(ax, ax.get_xlim(), ax.get_ylim(), ax.get_autoscalex_on(), ax.get_autoscaley_on(),
             ax.get_position(original=True), ax.get_in_layout()) for ax in fig.axes]


def _restore(view) -> None:
    for ax, xlim, ylim, autox, autoy, place, in_layout in view:
        ax.set_xlim(xlim)
        ax.set_ylim(ylim)
        ax.set_autoscalex_on(autox)
        ax.set_autoscaley_on(autoy)
        ax.set_position(place)
        ax.set_in_layout(in_layout)      # set_position takes the axes out of the layout


@contextlib.contextmanager
def _drawn(explorer, column: bool):
    """The explorer's figure as the page shows it: for the website's column (`site_figures`), or at
    its natural resolution (the slides, as JupyterLab); yields the resolution in dots per inch."""
    from .site_figures import drawn_for_the_column
    fig = explorer.fig
    if column:
        with drawn_for_the_column(fig, explorer.natural_dpi):
            yield fig.dpi
        return
    own = fig.dpi
    fig.set_dpi(explorer.natural_dpi)
    try:
        yield fig.dpi
    finally:
        fig.set_dpi(own)


def _webp(rgba) -> bytes:
    """Lossless WebP of the canvas' pixels (opaque: the alpha channel is left out)."""
    from PIL import Image   # matplotlib's own image library
    buf = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(np.asarray(rgba)[..., :3])).save(
        buf, format="webp", lossless=True, quality=20, method=1)   # 0.03 s, 1.2 times the smallest
    return buf.getvalue()


def _smallest_text_pt(fig) -> float | None:
    """Of a frame just rendered (`_render`): no second draw."""
    from .site_figures import smallest_text_pt
    return smallest_text_pt(fig, drawn=True)


def _move(explorer, settings: dict, defaults: dict, view) -> None:
    """One move from the defaults to `settings`, at rest (see the module's doc)."""
    _restore(view)
    try:
        explorer.apply(settings)
        explorer.error = None
    except Exception as error:   # noqa: BLE001 - shown as JupyterLab shows it: the figure stays
        explorer.error = f"{type(error).__name__}: {error}"
        explorer.apply(defaults)


def render_laid_out(explorer) -> None:
    """Render the explorer's figure laid out for what it shows now, in one layout pass from where
    its axes stand: for a frame, where the defaults' layout put them (`_move` puts them back), so
    that the frame does not depend on the frames drawn before it (constrained layout counts the
    ticks of the axes as they stand, so its result depends on where they stood). A second pass
    would move the axes of most frames by less than 2 pixels; JupyterLab, which lays a figure
    out again only when its text measures otherwise, does not make it either."""
    explorer.frames.relayout()
    explorer.frames.render()


def _inside_its_axes(artist) -> bool:
    """Whether constrained layout leaves `artist` out: hidden, out of the layout, or clipped to its
    axes (a curve, a marker; a text is not clipped and may reach past the axes)."""
    box = artist.get_clip_box() if artist.get_clip_on() else None
    return (not artist.get_visible() or not artist.get_in_layout()
            or (artist.axes is not None and box is not None and box.bounds == artist.axes.bbox.bounds))


def _render(explorer, laid: dict) -> None:
    """Render the frame of the settings just applied (`_move`). Its layout would be that of the frame
    laid out last (`laid`: its state before and its axes after the layout) when it starts from the
    same state (the same text, limits and places: `FrameRenderer.state`) and changed nothing the
    layout measures (only artists inside their axes): the axes are put where that layout put them,
    and the frame is blitted over its background; else it is laid out (`render_laid_out`)."""
    frames = explorer.frames
    before = frames.state()
    if laid.get("before") == before and all(map(_inside_its_axes, frames.changed())):
        _restore(laid["after"])
        frames.render()
        return
    render_laid_out(explorer)
    laid.update(before=before, after=_view(explorer.fig))


def _one_frame(explorer, settings: dict, defaults: dict, view, dpi: float, laid: dict) -> dict:
    """The frame of `settings`: one move from the defaults, at rest (`laid`: see `_render`)."""
    _move(explorer, settings, defaults, view)
    _render(explorer, laid)
    text = explorer.text
    width, height = explorer.frames.canvas.get_width_height(physical=True)
    return dict(image=_webp(explorer.frames.canvas.buffer_rgba()), alt=explorer.alt_for(text, settings),
                readout=text, smallest_text_pt=_smallest_text_pt(explorer.fig), dpi=dpi,
                width=width, height=height)


def _drawing_order(explorer, states_settings: list[dict], defaults: dict, view) -> list[int]:
    """The settings' indices with those whose figures share axes, limits and labels next to each
    other: a frame is blitted over the previous one's background when they match (`_render`; a
    full draw costs ten times more), and the results computed here are cached for the frames."""
    keys = []
    for settings in states_settings:
        _move(explorer, settings, defaults, view)
        keys.append(repr(explorer.frames.state()))
    return sorted(range(len(states_settings)), key=keys.__getitem__)


def render_frames(explorer, states_settings: list[dict], *, column: bool) -> list[dict]:
    """The frame of each settings dict of `states_settings` (name -> value): ``image`` (WebP
    bytes), ``alt`` and ``readout`` (the explorer's own for those settings), ``smallest_text_pt``,
    ``dpi``, ``width``, ``height``. The explorer is left at its defaults as it was."""
    defaults, error, view = explorer.params, explorer.error, _view(explorer.fig)
    try:
        with _drawn(explorer, column) as dpi:
            explorer.frames.reset()      # measuring the text for the column drew it at its own size:
            explorer.frames.relayout()   # its axes moved
            frames, laid = {}, {}
            for i in _drawing_order(explorer, states_settings, defaults, view):
                frames[i] = _one_frame(explorer, states_settings[i], defaults, view, dpi, laid)
            return [frames[i] for i in range(len(states_settings))]
    finally:
        _restore(view)
        explorer.error = error
        explorer.apply(defaults)
        explorer.frames.reset()
        explorer.frames.relayout()


def explorer_data(explorer, *, column: bool, max_frames: int = MAX_FRAMES) -> dict:
    """What a static page needs of `explorer` (JSON): its title, controls, stored states and
    their frames (base64 WebP), within `FRAME_BUDGET` (fewer frames when the first is large)."""
    first = render_frames(explorer, [explorer.params], column=column)[0]
    allowed = min(max_frames, max(1, int(FRAME_BUDGET / (1.5 * len(first["image"])))))
    while True:
        chosen = plan(explorer, allowed)
        frames = render_frames(explorer, [_settings(chosen["controls"], s) for s in chosen["states"]],
                               column=column)
        total = sum(len(f["image"]) for f in frames)
        if total <= FRAME_BUDGET:
            break
        if allowed <= 1:
            raise RuntimeError(f"the explorer {explorer.title!r}: one frame takes {total} bytes, more than "
                               f"the {FRAME_BUDGET} a static page allows; draw a smaller figure")
        allowed = max(1, int(allowed * FRAME_BUDGET / total * 0.9))
    for frame in frames:
        frame["image"] = base64.b64encode(frame["image"]).decode("ascii")
    controls = [{**c, "values": [v if isinstance(v, (int, float, str)) else str(v) for v in c["values"]]}
                for c in chosen["controls"]]
    return dict(title=explorer.title, controls=controls, states=[list(s) for s in chosen["states"]],
                full=chosen["full"], frames=frames)


def install(shell, *, column: bool) -> None:
    """Make `shell` (the kernel executing a notebook for a static page) add `explorer_data` under
    `MIME` to the display data of every explorer it shows: drawn for the website's column when
    `column`, else at the explorer's natural size (the slides)."""
    from IPython.core.formatters import JSONFormatter
    from traitlets import Unicode

    from ..explorers import Explorer

    class StaticExplorerFormatter(JSONFormatter):
        format_type = Unicode(MIME)

    display = shell.display_formatter
    formatter = StaticExplorerFormatter(parent=display)
    formatter.for_type(Explorer, lambda explorer: explorer_data(explorer, column=column))
    # first, before a formatter draws the figure (the website's draws it for the column and back,
    # which moves its axes): the frames start where the explorer laid its axes out, as JupyterLab's
    display.formatters = {MIME: formatter, **{k: v for k, v in display.formatters.items() if k != MIME}}
    display.active_types = [*display.active_types, MIME]


def _note(data: dict) -> str:
    menus = [c["label"] for c in data["controls"] if c["kind"] == "select"]
    choices = f" (each choice of {', '.join(menus)})" if menus else ""
    if data["full"]:
        return (f"Live on this page: every combination of the values the sliders stop at{choices}, "
                "computed when the page was built; JupyterLab computes every setting.")
    return (f"Live on this page: one slider at a time, the others at their defaults{choices}; moving one "
            "brings the others back. JupyterLab has every combination.")


def _control_html(control: dict, j: int, ident: str) -> str:
    cid, esc = f"{ident}-c{j}", html.escape
    label = f'<label for="{cid}">{esc(control["label"])}</label>'
    default = control["default"]
    if control["kind"] == "select":
        options = "".join(f'<option value="{i}"{" selected" if i == default else ""}>{esc(t)}</option>'
                          for i, t in enumerate(control["texts"]))
        return f'<div class="ck-static-control">{label}<select id="{cid}" data-ck-control="{j}">{options}</select></div>'
    text = esc(control["texts"][default])
    return (f'<div class="ck-static-control">{label}<input type="range" id="{cid}" min="0" '
            f'max="{len(control["values"]) - 1}" step="1" value="{default}" aria-valuetext="{text}" '
            f'data-ck-control="{j}"><span class="ck-static-value" aria-hidden="true">{text}</span></div>')


def explorer_html(data: dict, sources: list[str], *, ident: str) -> str:
    """The HTML block of one explorer: `data` from `explorer_data`, `sources` the address of each
    frame (in the order of ``data["frames"]``), `ident` unique on the page (the inputs' ids)."""
    if len(sources) != len(data["frames"]):
        raise ValueError(f"sources must give one address per frame: received {len(sources)} for "
                         f"{len(data['frames'])} frames.")
    controls = data["controls"]
    states = {",".join(map(str, s)): n for n, s in enumerate(data["states"])}
    first = data["frames"][states[",".join(str(c["default"]) for c in controls)]]
    script = dict(frames=[dict(src=src, alt=f["alt"], readout=f["readout"]) for src, f in zip(sources, data["frames"])],
                  states=states, defaults=[c["default"] for c in controls], kinds=[c["kind"] for c in controls],
                  texts=[c["texts"] for c in controls], values=[c["values"] for c in controls])
    payload = json.dumps(script, separators=(",", ":")).replace("</", "<\\/")
    readout = "<br>".join(html.escape(line) for line in first["readout"].split("\n"))
    inputs = "".join(_control_html(c, j, ident) for j, c in enumerate(controls))
    src = sources[data["frames"].index(first)]
    return (f'<div class="ck-static-explorer" id="{ident}">'
            f'<p class="ck-static-title"><b>{html.escape(data["title"])}</b></p>'
            f'<div class="ck-static-controls">{inputs}</div>'
            f'<p class="ck-static-note">{html.escape(_note(data))}</p>'
            f'<div class="ck-static-readout">{readout}</div>'
            f'<img class="ck-static-figure" src="{html.escape(src)}" alt="{html.escape(first["alt"])}" '
            f'width="{first["width"]}" height="{first["height"]}">'
            f'<div class="ck-static-live" role="status" aria-live="polite"></div>'
            f'<script type="application/json" class="ck-static-data">{payload}</script></div>')


def publish(nb, folder: Path, url: str, *, stem: str) -> list[dict]:
    """Write the frames of every explorer of the executed notebook `nb` into `folder` (as
    ``{stem}-{k}/{n}.webp``, addressed as ``{url}/{stem}-{k}/{n}.webp`` from the page) and put
    the explorer's HTML in place of its output, its fallback output removed (in place). Returns
    one entry per frame written: ``{"sha256", "bytes", "smallest_text_pt", "dpi"}``."""
    from ..explorers._fallback import is_fallback
    folder, written, count = Path(folder), [], 0
    for cell in nb.cells:
        if "outputs" in cell:       # the explorer's fallback for a reopened notebook: not shown here
            cell["outputs"] = [output for output in cell["outputs"] if not is_fallback(output)]
        for output in cell.get("outputs", []):
            data = output.get("data", {})
            if MIME not in data:
                continue
            entry = data[MIME]
            count += 1
            name = f"{stem}-{count}"
            (folder / name).mkdir(parents=True, exist_ok=True)
            sources = []
            for n, frame in enumerate(entry["frames"]):
                image = base64.b64decode(frame["image"])
                (folder / name / f"{n}.webp").write_bytes(image)
                sources.append(f"{url}/{name}/{n}.webp")
                written.append(dict(sha256=hashlib.sha256(image).hexdigest(), bytes=len(image),
                                    smallest_text_pt=frame["smallest_text_pt"], dpi=frame["dpi"]))
            output["data"] = {"text/html": explorer_html(entry, sources, ident=f"ck-{stem}-{count}")}
            output["metadata"] = {}
    return written


def copy_assets(folder: Path) -> None:
    """Copy the script and the style sheet of the static explorers into `folder`."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    for name in ASSET_FILES:
        shutil.copyfile(_TEMPLATES / name, folder / name)


def check_site_budget(frames: list[dict], *, what: str) -> None:
    """Raise RuntimeError when the frames written (entries of `publish`) pass `SITE_BUDGET`."""
    total = sum(f["bytes"] for f in frames)
    if total > SITE_BUDGET:
        raise RuntimeError(f"{what}: the explorers' frames take {total / 1e6:.1f} MB, more than the "
                           f"{SITE_BUDGET / 1e6:.0f} MB allowed; lower MAX_FRAMES in "
                           "coursekit.tools.static_explorers")
