"""``sl.controller(type, nomoto=(K, T))``: the design context carries the Nomoto model itself,
so K and T may have either sign (the same one): a course-unstable model is ``K < 0, T < 0``."""

from __future__ import annotations

import pytest

from steerlab.components.design import NomotoModel, design_context
from steerlab.control.design_model import design_model
from steerlab.errors import InputError


@pytest.mark.parametrize("K,T", [(0.05, 80.0), (-0.05, -120.0), (-0.0765, -409.0)])
def test_the_context_gives_K_T_with_their_signs_and_b2_K_over_T(K, T):
    ctx = design_context(nomoto=(K, T))
    assert isinstance(ctx.ship, NomotoModel)
    assert ctx.nomoto() == (K, T)
    assert ctx.b2("exact") == K / T > 0.0
    m = design_model(ctx)
    assert (m.K, m.T, m.unstable) == (K, T, T < 0.0)
    assert m.b == K / T and m.a == 1.0 / T


def test_given_b2_and_length_are_kept():
    ctx = design_context(nomoto=(-0.05, -120.0), b2=0.002, length_m=60.0)
    assert ctx.b2("exact") == 0.002
    assert ctx.ship.dims[1] == 60.0


@pytest.mark.parametrize("nomoto", [(0.05, -120.0), (-0.05, 120.0), (0.0, 50.0), (0.05, 0.0),
                                    (float("nan"), 50.0), (0.05,), "ab"])
def test_a_bad_model_is_one_line_naming_nomoto(nomoto):
    with pytest.raises(InputError) as ei:
        design_context(nomoto=nomoto)
    assert ei.value.field == "nomoto" and "\n" not in str(ei.value)


def test_opposite_signs_say_which_pair_would_do():
    with pytest.raises(InputError, match=r"\(-0.05, -120\)"):
        design_context(nomoto=(0.05, -120.0))


def test_bad_length_names_length_m():
    with pytest.raises(InputError) as ei:
        design_context(nomoto=(0.05, 80.0), length_m=-1.0)
    assert ei.value.field == "length_m"
