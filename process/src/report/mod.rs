//! The processing report: a self-contained HTML page with plots and tables.
