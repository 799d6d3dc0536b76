#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| cellrt_fuzz::ethercat::frame(data));
