"""``rocksweep accuracy`` (to be written)."""
