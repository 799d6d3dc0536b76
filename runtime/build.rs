//! Compiles the recording schema with protox (no protoc needed) and generates prost types.

use prost::Message;

fn main() {
    println!("cargo:rerun-if-changed=proto/cellrt.proto");
    let fds =
        protox::compile(["proto/cellrt.proto"], ["proto"]).expect("compile proto/cellrt.proto");
    let out = std::path::PathBuf::from(std::env::var("OUT_DIR").expect("OUT_DIR"));
    std::fs::write(out.join("cellrt.fds.bin"), fds.encode_to_vec()).expect("write descriptor set");
    prost_build::Config::new()
        .compile_fds(fds)
        .expect("generate prost code");
}
