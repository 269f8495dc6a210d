"""The notebook's own text in lecture mode: larger markdown, code, outputs and widgets.

`lecture_mode` (in `coursekit.style`) calls `show_lecture_text` so that one call prepares a
notebook for a projector. Run in a notebook cell, it displays an output that holds only a
``<style>`` element: CSS that sets JupyterLab's own size variables (``--jp-content-font-size1``
for markdown and HTML outputs, ``--jp-code-font-size`` for code and text outputs,
``--jp-ui-font-size1``, the prompt width and the ipywidgets sizes) on the notebook that shows
the output, and hides the output's own (empty) row. JupyterLab 4 and Notebook 7 (the same
notebook widget) read these variables, so every cell follows, those above the call too.

The rule applies only inside a live notebook (an element of class
``jp-NotebookPanel-notebook`` that holds the "on" ``<style>``): other open notebooks, the rest
of JupyterLab, nbconvert's HTML and slides and the course website (none has such an element
around the output; nor have GitHub's and nbviewer's renderings) keep their sizes even when the
output is stored; JupyterLab removes the ``<style>`` from outputs it does not trust (a
notebook saved by someone else). Switching off (``show_lecture_text(False)``) replaces every output shown with
`DISPLAY_ID` in this kernel session, through IPython's ``update_display``, by an "off" style
that only hides its row; running or clearing the cell does the same. JupyterLab forgets display
ids when the kernel restarts, so outputs made before a restart stay until their cell runs again
or is cleared. The output carries no ``text/plain`` form, so front ends that show no HTML show
nothing at all.

Outside a notebook kernel (plain Python, a terminal IPython, the tests) nothing is displayed.
JupyterLab's windowing mode "full" detaches cells scrolled out of view from the page, and with
them the style; the default mode ("contentVisibility") keeps every cell attached.
"""

from __future__ import annotations

__all__ = ["LECTURE_TEXT_SIZES", "DISPLAY_ID", "lecture_text_html", "show_lecture_text"]

#: the CSS variables lecture mode sets on the notebook, and their values (JupyterLab's
#: defaults: content 14px, code 13px, UI 13px, prompt 64px; ipywidgets: 13px text,
#: 28px rows, 80px labels, 300px controls, 16px slider handles); about one and a half times
#: the defaults, the explorers' lecture sizes (coursekit/explorers/view.css) for widgets
LECTURE_TEXT_SIZES = {
    "--jp-content-font-size1": "21px",
    "--jp-code-font-size": "20px",
    "--jp-ui-font-size1": "20px",
    "--jp-cell-prompt-width": "96px",
    "--jp-widgets-font-size": "20px",
    "--jp-widgets-inline-height": "40px",
    "--jp-widgets-inline-label-width": "120px",
    "--jp-widgets-inline-width": "450px",
    "--jp-widgets-slider-handle-size": "22px",
}

#: the display id of the style output: ``update_display`` finds every such output by it
DISPLAY_ID = "coursekit-lecture-mode"

#: the attribute that marks the style element of each state (the rule that enlarges the text
#: looks for the "on" one; a notebook holding only "off" outputs keeps its sizes)
_MARKS = {True: 'data-coursekit="lecture-mode-on"', False: 'data-coursekit="lecture-mode-off"'}


def lecture_text_html(on: bool = True) -> str:
    """The ``<style>`` element of the output: with `on`, the rule that enlarges the text of the
    notebook showing it; always, a rule that hides the (empty) output row that holds it."""
    mark = _MARKS[bool(on)]
    sizes = "".join(f"\n  {name}: {value};" for name, value in LECTURE_TEXT_SIZES.items())
    enlarge = f".jp-NotebookPanel-notebook:has(style[{mark}]) {{{sizes}\n}}\n" if on else ""
    return (f"<style {mark}>\n{enlarge}"
            f".jp-OutputArea-child:has(style[{mark}]) {{ display: none; }}\n"
            "</style>")


def _notebook_shell():
    """The IPython shell of a notebook kernel running this code, else None."""
    try:
        from IPython import get_ipython
    except ImportError:
        return None
    shell = get_ipython()
    return shell if getattr(shell, "kernel", None) is not None else None


def show_lecture_text(on: bool) -> bool:
    """Display (`on` true) or remove (`on` false) the style output in the running notebook.

    Returns True when a notebook kernel received it, False outside a notebook (nothing done).
    Switching on displays a new output each time (re-running the cell that switched it on
    replaces that cell's output); switching off turns every output this kernel session showed
    with `DISPLAY_ID` into the "off" style (`lecture_text_html(False)`).
    """
    if _notebook_shell() is None:
        return False
    from IPython.display import display, update_display
    data = {"text/html": lecture_text_html(on)}
    if on:
        display(data, raw=True, display_id=DISPLAY_ID)
    else:
        update_display(data, raw=True, display_id=DISPLAY_ID)
    return True
