"""rocksweep.fields: the one definition of a result field, a record variable and a stored
value as plain Python."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from rocksweep import fields
from rocksweep.vocab.ground import RECORD_IMS, SA, SCALE_IMS


@pytest.mark.parametrize("stored, want", [
    (np.bytes_(b"safe"), "safe"), (b"\xffok", "\ufffdok"), (np.int8(-1), -1),
    (np.float32(0.5), 0.5), (np.array(3.0), 3.0), (np.str_("mode1"), "mode1"),
    ("text", "text"), (None, None)])
def test_plain_gives_python_values(stored, want):
    got = fields.plain(stored)
    assert got == want and type(got) is type(want)


def test_plain_makes_nan_json_null_only_when_asked():
    assert math.isnan(fields.plain(np.float64("nan")))
    assert fields.plain(np.float64("nan"), nan_to_none=True) is None
    assert fields.plain(float("inf"), nan_to_none=True) is None
    assert json.dumps([fields.plain(np.float64(v), nan_to_none=True)
                       for v in (1.5, math.nan)]) == "[1.5, null]"


def test_record_variables_carry_the_vocabulary_units():
    for name, (var, unit, _n) in RECORD_IMS.items():
        assert fields.RECORD_VARIABLES[var][1] == unit, name
    assert fields.RECORD_VARIABLES["record_sa"][1] == SCALE_IMS[SA]
    assert "5% damping" in fields.RECORD_VARIABLES["record_sa"][2]


def test_a_blocks_attributes_name_its_alpha():
    block = fields.field_attrs(fields.BY_NAME["theta_max_over_alpha"], "block")
    flexible = fields.field_attrs(fields.BY_NAME["theta_max_over_alpha"], "flexible")
    assert "alpha_cg" not in str(block) and "alpha" in block["rocksweep_units"]
    assert "alpha_cg" in flexible["rocksweep_units"]
    assert fields.axis_attrs("A_ratio", "block")["symbol"] == "A/(g tan alpha)"
