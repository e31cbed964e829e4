"""Captures from other tools (COLMAP models, nerfstudio transforms.json) read for refinement and written
back in their own format: `read_views`, `write_kept`, `require_depth` (`render.captures.open`)."""
