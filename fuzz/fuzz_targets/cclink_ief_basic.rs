#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| cellrt_fuzz::fieldbus::cclink_ief_basic(data));
