"""Bad input in Python: the ValueError a call raises, checked to be one line holding each
expected fragment."""

from __future__ import annotations

import pytest


def one_line_value_error(call, *fragments) -> str:
    """The message of the ValueError ``call()`` raises: one line, holding every fragment."""
    with pytest.raises(ValueError) as err:
        call()
    msg = str(err.value)
    assert "\n" not in msg, msg
    for fragment in fragments:
        assert fragment in msg, msg
    return msg
