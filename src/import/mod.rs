//! Importers for tracking-tool exports (filled in by the import work).
