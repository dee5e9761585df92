"""The durable job queue of every kind of ``gearengine.studies.jobs.KINDS``: SQLite store,
dispatcher (process pool or Dask), worker command."""
