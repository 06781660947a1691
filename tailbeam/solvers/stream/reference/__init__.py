"""The slow, independent reference of the stream solver: every pair watched, scipy's DOP853
step by step, on the rigid or the modal plate (``solver``)."""
