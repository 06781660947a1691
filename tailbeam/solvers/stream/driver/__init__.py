"""The fast stream solver's event-driven driver: closed-form balls (``balls``), their heap of
predicted events (``heap``, ``broadphase``) and what is done when one comes due
(``heap_events``), which balls the active set integrates (``membership``), what it reports
(``set_events``), the contact records (``records``), the plate's loads (``loads``), the
energy ledger (``energy``), the time and counters (``clock``) and the loop that wires them
(``loop``)."""
