import os

import jax
import pytest

# the CLI's persistent compilation cache stays off in tests (hermetic; test_cli checks it on)
os.environ.setdefault("JAXCELT_CACHE_DIR", "off")

jax.config.update("jax_enable_x64", True)
jax.config.update("jax_numpy_rank_promotion", "raise")


@pytest.fixture(scope="session")
def paper_params():
    import jaxcelt

    return jaxcelt.CeltParams.paper()
