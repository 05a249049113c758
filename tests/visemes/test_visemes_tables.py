"""The viseme rules as data: names, phone map, FAP targets from their definitions."""

from __future__ import annotations

import numpy as np
import pytest

from facelib.errors import ParameterError
from facelib.mpeg4.tables import fap, fap_table
from facelib.visemes import driven_faps, phone_viseme, script_name, viseme_id, viseme_targets

CMU_PHONES = (
    "AA", "AE", "AH", "AO", "AW", "AY", "B", "CH", "D", "DH", "EH", "ER", "EY", "F", "G", "HH",
    "IH", "IY", "JH", "K", "L", "M", "N", "NG", "OW", "OY", "P", "R", "S", "SH", "T", "TH",
    "UH", "UW", "V", "W", "Y", "Z", "ZH",
)


def v(name: str, fap_name: str) -> float:
    return float(viseme_targets()[viseme_id(name), fap(fap_name).index])


@pytest.mark.parametrize(
    ("name", "expected"),
    [("silence", 0), ("A", 10), ("kg", 5), ("Q", 13), ("nl", 8), ("sz", 7), ("I", 12),
     ("TD", 3), ("td", 4), ("PP", 1), ("pp", 1), ("ou", 14), ("14", 14), (9, 9)],
)
def test_script_and_mpeg4_names(name, expected):
    assert viseme_id(name) == expected


def test_unknown_viseme_name_is_named():
    with pytest.raises(ParameterError, match="'xyz'"):
        viseme_id("xyz")


def test_script_names_round_trip():
    for vid in range(15):
        assert viseme_id(script_name(vid)) == vid


def test_every_cmu_phone_has_annex_b_viseme():
    expected = {"P": 1, "B": 1, "M": 1, "F": 2, "V": 2, "TH": 3, "DH": 3, "T": 4, "D": 4,
                "K": 5, "G": 5, "CH": 6, "JH": 6, "SH": 6, "S": 7, "Z": 7, "N": 8, "L": 8,
                "R": 9, "AA": 10, "EH": 11, "IH": 12, "IY": 12, "UW": 14, "W": 14}
    for phone in CMU_PHONES:
        rule = phone_viseme(phone + "1")
        assert all(0 <= x <= 14 for x in rule.visemes)
        if phone in expected:
            assert rule.visemes == (expected[phone],)
    assert phone_viseme("AY").visemes == (10, 12)
    assert phone_viseme("OW").visemes == (13, 14)
    with pytest.raises(ParameterError, match="QQ"):
        phone_viseme("QQ")


def test_targets_match_viseme_definitions():
    # p b m: lips pressed together (upper lip down, lower lip up), jaw nearly closed
    assert v("PP", "lower_t_midlip") > 0 and v("PP", "raise_b_midlip") > 0
    assert v("PP", "open_jaw") < 50
    # f v: lower lip up and back under the upper teeth
    assert v("FF", "raise_b_midlip") > 150 and v("FF", "push_b_lip") < 0
    # th: tongue tip forward between the teeth
    assert v("TH", "thrust_tongue_tip") > 150
    # t d n l: tongue tip raised; k g: tongue back raised
    assert v("DD", "raise_tongue_tip") > 250 and v("nn", "raise_tongue_tip") > 250
    assert v("kk", "raise_tongue") > 250
    # aa is the widest open; ou rounded and protruded; ih spread
    jaw = viseme_targets()[:, fap("open_jaw").index]
    assert int(np.argmax(jaw)) == viseme_id("aa")
    # (lip-corner stretch is on the inner corners only, at half the value: on the default
    # head it drives the learned mouthStretch field, which moves the outer corner too)
    assert v("ou", "push_t_lip") > 200 and v("ou", "stretch_l_cornerlip") < -150
    assert v("oh", "open_jaw") > v("ou", "open_jaw")
    assert v("ih", "stretch_l_cornerlip") > 100 and v("E", "stretch_l_cornerlip") > 75
    # silence is the neutral face
    assert not viseme_targets()[0].any()


def test_targets_symmetric_within_ranges_and_on_driven_faps():
    targets = viseme_targets()
    assert not targets[:, ~driven_faps()].any()
    for f in fap_table():
        col = targets[:, f.index]
        if f.min is not None:
            assert col.min() >= f.min and col.max() <= f.max, f.name
    for left, right in (("stretch_l_cornerlip", "stretch_r_cornerlip"),
                        ("raise_b_lip_lm", "raise_b_lip_rm"), ("lower_t_lip_lm", "lower_t_lip_rm")):
        np.testing.assert_array_equal(targets[:, fap(left).index], targets[:, fap(right).index])
    assert not targets.flags.writeable
