"""The HTTP service: ``lynxplan serve`` (FastAPI + uvicorn), its job store and its web page.

:mod:`.app` holds the routes only; :mod:`.compute` the array computations behind them (also run
on Dask workers); :mod:`.wire` the request/response encodings; :mod:`.jobs` the SQLite run store
and the worker pool.
"""
