"""Applications on top of the library: command line, studies, Gymnasium, views, comparisons,
validation, export."""
