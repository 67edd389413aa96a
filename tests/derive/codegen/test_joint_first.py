"""joint_first: the joint-first solve of M nu' = f holds only where its premise does."""
import pytest
import sympy as sp


def test_joint_first_solve_refuses_coupled_joints():
    from derive import dynamics as D
    from derive.codegen.joint_first import joint_first_system
    M = D.inertia().copy()
    M[3, 4] = M[4, 3] = sp.Symbol("c34")
    with pytest.raises(ValueError, match="M_34"):
        joint_first_system(M, D.rhs())
