"""``rocksweep plot`` (to be written)."""
