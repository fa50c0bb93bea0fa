"""The thesis's experiments as functions, with their tables beside the printed values.

lqg_tables      Table 6.1: SAS and CSAS with integral LQG on the linear pitch model (ch. 6)
shaping_tables  Table 4.2 (1-DOF): doublet shaped by low-pass and band-stop filters (ch. 4)
tables          the comparison-table type (computed value beside the thesis's, with notes)
"""

from .lqg_tables import plot_table_6_1, table_6_1, table_6_1_sensitivity
from .shaping_tables import table_4_2
from .tables import ComparisonTable

__all__ = ["ComparisonTable", "plot_table_6_1", "table_4_2", "table_6_1", "table_6_1_sensitivity"]
