//! The file formats' integration tests, one binary: round trips, regions and
//! tags, the tripod in every format, surface (PLC) readers, indicators.

#[path = "../support/mod.rs"]
mod support;

mod indicator;
mod plc_readers;
mod regions;
mod roundtrip;
mod tripod_formats;
