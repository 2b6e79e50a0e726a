"""Type aliases shared by the stubs (importable at run time too)."""

from typing import Any, Sequence, Union

import numpy as np
import numpy.typing as npt

#: A float64 array returned by the vectorized functions.
FloatArray = npt.NDArray[np.float64]
#: What the vectorized functions accept: a float or any array-like of floats.
ArrayLike = npt.ArrayLike
#: Array-likes that are not plain floats (selects the array-returning overload).
ArrayIn = Union[npt.NDArray[Any], Sequence[Any]]

__all__ = ["ArrayIn", "ArrayLike", "FloatArray"]
