"""Periodic motion: from poses to a circular coordinate, a periodic density and a typical cycle.

The modules follow the data: :mod:`.preprocess` prepares the poses, :mod:`.landmarks` picks
the frames the filtration is built on, :mod:`.barcode` computes the persistent cohomology
barcode with cocycles, :mod:`.coordinates` turns a cocycle into a circular coordinate,
:mod:`.density` and :mod:`.cycle` build the typical cycle, :mod:`.pipeline` runs them in
order (:func:`~cyclecoord.periodic.pipeline.extract`), :mod:`.phase_model` phases new
frames with a fitted coordinate and :mod:`.detection` (a subpackage, one module per
stage) finds several motions in one take.
"""
