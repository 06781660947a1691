"""What every solver reports: event and contact records (``records``) and the one result
type of ``tailbeam.simulate`` (``result``)."""
