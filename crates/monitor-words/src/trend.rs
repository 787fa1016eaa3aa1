//! The trend's words: the alarm, each indicator's line and the reference, spelled from
//! [`monitor_store::trend`]'s typed values.
