"""Generated model helpers (meshes written to a cache folder, never to the repository)."""
