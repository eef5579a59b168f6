"""The typed checks of a config's values (epc_fast.jobs.schema): each message names the config
of the command reading it."""

import pytest

from epc_fast.jobs.errors import ConfigError, TooLargeError
from epc_fast.jobs.schema import config_of, config_prefix, integer, number_list, take


def test_a_message_names_the_config_of_the_command_reading_it():
    with config_of("optimize"):
        with pytest.raises(ConfigError, match=r"^optimize config \[optimize\]: points = 0: "
                                              r"expected an integer between 1 and 10"):
            integer("optimize", "points", 0, 1, 10)


def test_the_command_is_restored_after_its_block_even_after_an_error():
    with config_of("scan"):
        with pytest.raises(ConfigError), config_of("sobol"):
            take({"extra": 1}, "sobol")
        assert config_prefix() == "scan config"
    assert config_prefix() == "config"


def test_a_size_beyond_its_bound_is_too_large_naming_the_config():
    with config_of("simulate"), pytest.raises(TooLargeError, match=r"^simulate config \[x\]"):
        number_list("x", "q", [0.5] * 1_000_001)
