"""Shape/dtype aliases (jaxtyping), kept in one place as diffrax does."""

from jaxtyping import Array, ArrayLike, Bool, Float, Int

Scalar = Float[Array, ""]
ScalarLike = float | Float[ArrayLike, ""]
Vec3 = Float[Array, "3"]
State = Float[Array, "13"]
"""The paper's state y = (v[3], omega[3], n[3], r_C[3], psi), MODEL.md section 8."""
Mat3 = Float[Array, "3 3"]

__all__ = ["Array", "ArrayLike", "Bool", "Float", "Int", "Mat3", "Scalar", "ScalarLike", "State", "Vec3"]
