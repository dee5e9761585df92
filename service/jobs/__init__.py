"""The durable job queue of every kind of ``gearengine.studies.jobs.KINDS``: the store (SQLite,
or PostgreSQL shared by replicas), dispatcher (process pool or Dask), worker command."""
