"""yoke_frame: the forms in the yoke frame equal those in the shell frame."""
from derive import yoke_frame as YF


def test_yoke_frame_forms_equal_the_shell_frame_forms():
    assert YF.check_equivalence() == [0] * 30
