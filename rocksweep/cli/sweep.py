"""``rocksweep sweep`` (to be written)."""
