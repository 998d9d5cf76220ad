"""Pictures and meshes: the rasteriser (numpy, Pillow, numba kernels byte-equal to it), scenes
with labels and legends (:mod:`.scene`), level pictures, meshes and their collision check."""
