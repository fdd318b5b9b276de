"""Answer key of the brightness assignment."""

import numpy as np


def average_brightness(image: np.ndarray) -> int:
    """The mean of all bytes of the image, rounded down (the contract's integer division)."""
    return int(image.sum(dtype=np.uint64) // image.size)
