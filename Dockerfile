# gearchaos: the API and sweep workers. Same install steps as `make run`.
FROM python:3.11-slim

ENV PYTHONDONTWRITEBYTECODE=1 PYTHONUNBUFFERED=1 \
    NUMBA_CACHE_DIR=/home/gearchaos/.numba-cache \
    GEARCHAOS_DATA_DIR=/data

RUN useradd --create-home --uid 10001 gearchaos && mkdir /data && chown gearchaos /data
WORKDIR /app
# extras to install beside the package, e.g. --build-arg EXTRAS="[dask]" for Dask workers
ARG EXTRAS=""
COPY pyproject.toml README.md ./
COPY gearengine ./gearengine
COPY service ./service
# pyunicorn (the signals' IAAFT surrogates) has no wheel for 3.11: it compiles with Cython
RUN apt-get update && apt-get install -y --no-install-recommends gcc g++ \
    && rm -rf /var/lib/apt/lists/*
RUN python -m pip install --no-cache-dir --upgrade pip \
    && python -m pip install --no-cache-dir ".${EXTRAS}"

USER gearchaos
VOLUME ["/data"]
EXPOSE 8000
HEALTHCHECK --interval=30s --timeout=5s --start-period=60s --retries=3 \
    CMD python -c "import urllib.request, sys; sys.exit(0 if urllib.request.urlopen('http://127.0.0.1:8000/v1/health', timeout=4).status == 200 else 1)"
CMD ["gearengine", "serve", "--host", "0.0.0.0"]
