"""fit_margins: fixed margins normally, constrained layout in lecture mode."""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402

import coursekit as ck  # noqa: E402


def test_fixed_margins_by_default_and_constrained_layout_in_lecture_mode():
    fig, _ = plt.subplots(1, 2)
    ck.fit_margins(fig, left=0.1, right=0.95, bottom=0.2, top=0.8, wspace=0.3)
    params = fig.subplotpars
    assert (params.left, params.right, params.bottom, params.top, params.wspace) == (0.1, 0.95, 0.2, 0.8, 0.3)
    assert fig.get_layout_engine() is None
    ck.lecture_mode(True)
    try:
        fig2, _ = plt.subplots()
        ck.fit_margins(fig2, left=0.1, right=0.95, bottom=0.2, top=0.8)
        assert type(fig2.get_layout_engine()).__name__ == "ConstrainedLayoutEngine"
    finally:
        ck.lecture_mode(False)
        plt.close("all")
