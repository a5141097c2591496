"""Drake as a second engine for planar prehensile pushes (``pip install 'regrasp[drake]'``):
:mod:`.push`."""
