"""The OpenGL 3D viewport: the material on a mesh, lit like the reference renderer, painted on.

Modules, one idea each (Qt and OpenGL live here only, never in the engine):

- :mod:`.context` — default surface format, an offscreen context for tests and benchmarks
- :mod:`.shaders` — GLSL sources (the BRDF of :mod:`matshop.render.brdf` written again)
  and program compilation
- :mod:`.fbo` — framebuffer objects with float or 8-bit attachments, read back as numpy
- :mod:`.mesh_data` — meshes (OBJ, glTF, a procedural sphere) as flat vertex arrays, with
  tangents computed when the file has none
- :mod:`.mesh_gpu` — those arrays in a VAO
- :mod:`.camera` — the orbit camera (matches :mod:`matshop.render.scenes` by default)
- :mod:`.shading_maps` — document physical maps -> packed shading textures and their mips
- :mod:`.sampled_lobe` — a sampled lobe's table and inverse-CDF nodes as one array texture
- :mod:`.textures` — shading textures on the GPU, dirty tiles re-uploaded with byte counts
- :mod:`.environment_gpu` — the environment's mip chain and irradiance map as textures
- :mod:`.renderer` — the draw (background, shaded mesh), offscreen images
- :mod:`.banded_frame` — a frame too slow for one paint drawn in row bands, the last whole
  frame shown meanwhile
- :mod:`.swatch` — the same shader in texture space: the lit swatch, one pixel per texel
- :mod:`.picking` — the UV/position pass: cursor -> surface point and texture coordinate
- :mod:`.surface_map` — every texel's surface point (a UV-space bake), for 3D dabs
- :mod:`.painting` — strokes on the mesh through the brush engine
- :mod:`.view` — :class:`MaterialViewport`, the QOpenGLWidget
"""
