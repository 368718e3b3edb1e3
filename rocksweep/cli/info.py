"""``rocksweep info`` (to be written)."""
