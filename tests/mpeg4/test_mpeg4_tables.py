"""The FAP and feature-point tables against annex A of the thesis (tables A.1-A.3)."""

import pytest

from facelib import ParameterError, fap, feature_point
from facelib.mpeg4 import ANGLE_UNIT, FAPU_NAMES, N_FAPS, fap_table, feature_point_table

# Annex A, table A.1: id -> (name, U/B, group). The thesis prints 'raise_b_lip_rm_o' for
# both 57 and 58 (a typo: 57 is the left one, its description says "esquerdo").
ANNEX_A1 = """
1 viseme - 1|2 expression - 1|3 open_jaw U 2|4 lower_t_midlip B 2|5 raise_b_midlip B 2
6 stretch_l_cornerlip B 2|7 stretch_r_cornerlip B 2|8 lower_t_lip_lm B 2|9 lower_t_lip_rm B 2
10 raise_b_lip_lm B 2|11 raise_b_lip_rm B 2|12 raise_l_cornerlip B 2|13 raise_r_cornerlip B 2
14 thrust_jaw U 2|15 shift_jaw B 2|16 push_b_lip B 2|17 push_t_lip B 2|18 depress_chin B 2
19 close_t_l_eyelid B 3|20 close_t_r_eyelid B 3|21 close_b_l_eyelid B 3
22 close_b_r_eyelid B 3|23 yaw_l_eyeball B 3|24 yaw_r_eyeball B 3|25 pitch_l_eyeball B 3
26 pitch_r_eyeball B 3|27 thrust_l_eyeball B 3|28 thrust_r_eyeball B 3
29 dilate_l_pupil B 3|30 dilate_r_pupil B 3|31 raise_l_i_eyebrow B 4
32 raise_r_i_eyebrow B 4|33 raise_l_m_eyebrow B 4|34 raise_r_m_eyebrow B 4
35 raise_l_o_eyebrow B 4|36 raise_r_o_eyebrow B 4|37 squeeze_l_eyebrow B 4
38 squeeze_r_eyebrow B 4|39 puff_l_cheek B 5|40 puff_r_cheek B 5|41 lift_l_cheek U 5
42 lift_r_cheek U 5|43 shift_tongue_tip B 6|44 raise_tongue_tip B 6
45 thrust_tongue_tip B 6|46 raise_tongue B 6|47 tongue_roll U 6|48 head_pitch B 7
49 head_yaw B 7|50 head_roll B 7|51 lower_t_midlip_o B 8|52 raise_b_midlip_o B 8
53 stretch_l_cornerlip_o B 8|54 stretch_r_cornerlip_o B 8|55 lower_t_lip_lm_o B 8
56 lower_t_lip_rm_o B 8|57 raise_b_lip_lm_o B 8|58 raise_b_lip_rm_o B 8
59 raise_l_cornerlip_o B 8|60 raise_r_cornerlip_o B 8|61 stretch_l_nose B 9
62 stretch_r_nose B 9|63 raise_nose B 9|64 bend_nose B 9|65 raise_l_ear B 10
66 raise_r_ear B 10|67 pull_l_ear B 10|68 pull_r_ear B 10
"""

# Table A.3, exactly: id, name, feature point, positive motion, FAPU (all bidirectional).
ANNEX_A3 = [
    (69, "STRETCH_T_LIP_LM", "2.6", "left", "MW"),
    (70, "STRETCH_T_LIP_RM", "2.7", "right", "MW"),
    (71, "STRETCH_B_LIP_LM", "2.8", "left", "MW"),
    (72, "STRETCH_B_LIP_RM", "2.9", "right", "MW"),
    (73, "STRETCH_T_LIP_LM_O", "8.5", "left", "MW"),
    (74, "STRETCH_T_LIP_RM_O", "8.6", "right", "MW"),
    (75, "STRETCH_B_LIP_LM_O", "8.7", "left", "MW"),
    (76, "STRETCH_B_LIP_RM_O", "8.8", "right", "MW"),
    (77, "STRETCH_T_LIP", "2.2", "right", "MW"),
    (78, "STRETCH_B_LIP", "2.3", "right", "MW"),
    (79, "STRETCH_T_LIP_O", "8.1", "right", "MW"),
    (80, "STRETCH_B_LIP_O", "8.2", "right", "MW"),
    (81, "NOSE_R_UP", "9.14", "up", "MNS"),
    (82, "NOSE_L_UP", "9.13", "up", "MNS"),
    (83, "NOSE_R_STRETCH", "9.14", "right", "MW"),
    (84, "NOSE_L_STRETCH", "9.13", "left", "MW"),
]

# Group sizes from table A.2 (group 11: the extended FAPs).
GROUP_SIZES = {1: 2, 2: 16, 3: 12, 4: 8, 5: 4, 6: 5, 7: 3, 8: 10, 9: 4, 10: 4, 11: 16}


def _annex_a1():
    for item in ANNEX_A1.replace("\n", "|").split("|"):
        if item.strip():
            fid, name, kind, group = item.split()
            yield int(fid), name, kind, int(group)


def test_table_has_84_faps_in_order():
    table = fap_table()
    assert len(table) == N_FAPS == 84
    assert [f.id for f in table] == list(range(1, 85))
    assert [f.index for f in table] == list(range(84))


@pytest.mark.parametrize(("fid", "name", "kind", "group"), list(_annex_a1()))
def test_standard_faps_match_annex_a1(fid, name, kind, group):
    row = fap(fid)
    assert row.name == name
    assert row.group == group
    assert row.bidirectional is {"U": False, "B": True, "-": None}[kind]
    assert not row.extended


@pytest.mark.parametrize(("fid", "name", "point", "direction", "fapu"), ANNEX_A3)
def test_extended_faps_match_annex_a3(fid, name, point, direction, fapu):
    row = fap(name)
    assert row.id == fid
    assert row.feature_points == (point,)
    assert row.positive_direction == direction
    assert row.fapu == fapu
    assert row.bidirectional is True
    assert row.extended
    assert row.kind == "translation"
    axis = {"left": "x", "right": "x", "up": "y"}[direction]
    assert row.axis == axis
    sign = {"left": 1, "right": -1, "up": 1}[direction]  # +x is the face's own left
    assert row.direction["xyz".index(axis)] == sign


def test_group_sizes_match_annex_a2():
    sizes: dict[int, int] = {}
    for row in fap_table():
        sizes[row.group] = sizes.get(row.group, 0) + 1
    assert sizes == GROUP_SIZES


def test_fapu_per_group():
    """Units follow the standard: eyelids IRISD, rotations AU, brows ENS (squeeze ES),
    mouth MNS vertically and MW horizontally."""
    for row in fap_table():
        assert row.fapu in (*FAPU_NAMES, "none")
        if row.kind == "rotation":
            assert row.fapu == "AU"
        if row.group in (2, 8, 11) and row.kind == "translation":
            assert row.fapu == ("MW" if row.axis == "x" else "MNS"), row.name
    assert [fap(i).fapu for i in (19, 20, 21, 22)] == ["IRISD"] * 4
    assert [fap(i).fapu for i in range(31, 37)] == ["ENS"] * 6
    assert fap("squeeze_l_eyebrow").fapu == "ES"
    assert fap("head_yaw").fapu == "AU"
    assert ANGLE_UNIT == 1e-5


def test_lookup_by_name_is_case_insensitive():
    assert fap("open_jaw") is fap("OPEN_JAW") is fap(3) is fap("3")
    assert fap("Stretch_T_Lip_LM").id == 69


def test_lookup_errors_name_the_value():
    with pytest.raises(ParameterError, match=r"open_jaww.*did you mean .open_jaw."):
        fap("open_jaww")
    with pytest.raises(ParameterError, match="85"):
        fap(85)
    with pytest.raises(ParameterError, match="0"):
        fap(0)
    with pytest.raises(ParameterError, match=r"2\.99"):
        feature_point("2.99")


def test_feature_points_link_back_to_their_faps():
    points = feature_point_table()
    assert len(points) == 84
    for row in fap_table():
        for point in row.feature_points:
            assert row.id in points[point].faps, (row.name, point)
    assert feature_point("3.5").side == "left"
    assert "MW0" in feature_point("8.3").fapu_uses


def test_directions_agree_with_positive_motion():
    """A translation's direction vector points the way its positive motion names."""
    words = {"left": (0, 1), "right": (0, -1), "up": (1, 1), "down": (1, -1),
             "forward": (2, 1)}
    for row in fap_table():
        if row.kind == "translation" and row.positive_direction in words:
            axis, sign = words[row.positive_direction]
            assert row.axis == "xyz"[axis]
            assert row.direction[axis] * sign > 0, row.name
