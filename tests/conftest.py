import jax
import pytest

jax.config.update("jax_enable_x64", True)
jax.config.update("jax_numpy_rank_promotion", "raise")


@pytest.fixture(scope="session")
def paper_params():
    import jaxcelt

    return jaxcelt.CeltParams.paper()
