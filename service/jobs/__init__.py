"""The durable sweep queue: SQLite store, dispatcher (process pool or Dask), worker command."""
