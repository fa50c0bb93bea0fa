"""Presentation of results: figures, side-by-side tables and report sections (matplotlib, no computation).

Modules
-------
trms.present.figures   plots drawn from results (spectra, steps, loops), each with units and a legend
trms.present.tables    tables of measured numbers beside the thesis's printed ones
trms.present.sections  a report section: its tables, figures and text
"""

__all__: list[str] = []
