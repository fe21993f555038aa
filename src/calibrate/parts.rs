//! Bundled relay parts.
