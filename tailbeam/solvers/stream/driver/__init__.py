"""The fast stream solver's event-driven driver: closed-form balls (``balls``), their heap of
predicted events (``heap``, ``broadphase``), which balls the active set integrates
(``membership``), what it reports (``set_events``), the records, loads and energy ledger
(``records``) and the loop (``loop``)."""
