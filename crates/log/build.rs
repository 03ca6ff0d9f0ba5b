//! Compiles `proto/ricochet.proto` with protox (a protobuf compiler in Rust: no `protoc`
//! needed) into Rust types (prost) and the FileDescriptorSet every log embeds as the
//! schema of Ricochet's channels.

fn main() -> Result<(), Box<dyn std::error::Error>> {
    println!("cargo:rerun-if-changed=proto/ricochet.proto");
    let files = protox::compile(["proto/ricochet.proto"], ["proto"])?;
    let out = std::path::PathBuf::from(std::env::var("OUT_DIR")?);
    std::fs::write(
        out.join("ricochet.fds"),
        prost::Message::encode_to_vec(&files),
    )?;
    prost_build::Config::new()
        // Maps as BTreeMap: encoded in key order, never in a HashMap's.
        .btree_map(["."])
        .compile_fds(files)?;
    Ok(())
}
