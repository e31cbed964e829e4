"""Shared plumbing below every other package: atomic file writes, JSON, the cache folder, provenance.

Nothing here imports `scenes`, `render` or `nbv`.
"""

from common.io import atomic_path, cache_dir, markdown_table, write_json, write_text
from common.provenance import config_record, git_commit

__all__ = ["atomic_path", "cache_dir", "config_record", "git_commit", "markdown_table", "write_json",
           "write_text"]
