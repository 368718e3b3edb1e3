"""Shared fixtures: the paper's bodies (Tables 2 and 3) and a CLI runner."""

import pytest
from click.testing import CliRunner

from rocksweep.model import FlexibleBody


@pytest.fixture(scope="session")
def body_fig2() -> FlexibleBody:
    """Table 2: stocky, laterally flexible body of Figure 2."""
    return FlexibleBody(wn_over_p=2.43, zeta=0.05, alpha_cg=0.35, alpha_A=0.6,
                        mA_over_m=0.47, IA_ratio=0.56)


@pytest.fixture(scope="session")
def body_fig3() -> FlexibleBody:
    """Table 3, Figure 3: slender flexible body (wn/p = 2.43)."""
    return FlexibleBody(wn_over_p=2.43, zeta=0.05, alpha_cg=0.15, alpha_A=0.28,
                        mA_over_m=0.47, IA_ratio=0.56)


@pytest.fixture(scope="session")
def body_fig4() -> FlexibleBody:
    """Table 3, Figure 4: slender stiff body (wn/p = 9.82)."""
    return FlexibleBody(wn_over_p=9.82, zeta=0.05, alpha_cg=0.15, alpha_A=0.28,
                        mA_over_m=0.47, IA_ratio=0.56)


@pytest.fixture()
def cli():
    return CliRunner()
