"""Every explorer's text alternative says what its figure shows, not only what its controls are set to.

The readout (which the text alternative ends with, and which a screen reader announces when a
slider rests) must carry at least one number taken from the computed data that changes when the
first slider moves by one step: the trajectory planner's peak speed, the upright pendulum's peak
torques, and so on. A readout that only repeats the settings and a verdict would tell a reader
who cannot see the figure nothing new after each step.
"""

import re

import pytest

from coursekit.tools.chapters import explorer_factories

EXPLORERS = explorer_factories()
NUMBER = re.compile(r"[-+\u2212]?\d+(?:\.\d+)?(?:e[-+]?\d+)?")


def _data_numbers(explorer, params: dict) -> list[str]:
    """The numbers of the readout for `params`, less the ones that only repeat a setting."""
    explorer.apply(params)
    echoes = {f"{v:g}" for v in params.values() if isinstance(v, (int, float))}
    return [n for n in NUMBER.findall(explorer.text) if n.lstrip("+-\u2212") not in echoes]


@pytest.mark.parametrize("name", sorted(EXPLORERS))
def test_the_readout_carries_a_number_of_the_data_that_follows_the_first_slider(name):
    explorer = EXPLORERS[name]()
    first, control = next(iter(explorer.controls.items()))
    step = control.step
    value = control.value + step if control.value + step <= control.max else control.value - step
    before = _data_numbers(explorer, explorer.params)
    after = _data_numbers(explorer, {**explorer.params, first: value})
    assert before != after, (f"{name}: moving {first} from {control.value} to {value} changes no number "
                             f"of the readout but the settings: {explorer.text!r}")
