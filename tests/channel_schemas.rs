//! Every channel Ricochet writes is protobuf with a protobuf schema (MCAP's protobuf
//! profile), and every schema is self-contained: its FileDescriptorSet defines the message
//! type it names and all it uses, so a reader needs nothing but the log. Lichtblick 1.10.8
//! (the open-source Foxglove Studio, run on every shipped scenario with
//! `../shared/viewer/view`) and the Python `mcap-protobuf-support` reader (CI) decode them
//! from the log alone.

use ricochet_log::LogFile;

use crate::util::{ricochet, root};

#[test]
fn every_channel_is_protobuf_and_every_message_decodes_from_its_schema_alone() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("v.mcap");
    let o = ricochet(
        &[
            "run",
            root().join("scenarios/shapes.toml").to_str().unwrap(),
            "--validate",
            "--frames",
            "30",
            "-o",
            out.to_str().unwrap(),
        ],
        b"",
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let log = LogFile::open(&out).unwrap();
    let channels: Vec<(&str, &str)> = log
        .channels()
        .map(|c| (c.topic.as_str(), c.schema_name.as_str()))
        .collect();
    assert_eq!(
        channels,
        [
            ("/scene", "foxglove.SceneUpdate"),
            ("/scene/static", "foxglove.SceneUpdate"),
            ("/tf", "foxglove.FrameTransforms"),
            ("/scene/contacts", "foxglove.SceneUpdate"),
            ("/bodies", "ricochet.Bodies"),
            ("/contacts", "ricochet.Contacts"),
            ("/stats", "ricochet.Stats"),
            ("/events", "foxglove.Log"),
            ("/validation", "ricochet.Validation"),
        ]
    );
    for c in log.channels() {
        assert_eq!(
            (c.message_encoding.as_str(), c.schema_encoding.as_str()),
            ("protobuf", "protobuf"),
            "{}",
            c.topic
        );
    }
    // Each message is decoded with a descriptor pool built from its channel's schema bytes
    // only; a schema that names a type it does not define, or misses an import, fails here.
    let mut decoded = 0;
    for m in log.messages().unwrap() {
        let m = m.unwrap();
        assert!(m.data.is_object(), "{}", m.topic);
        decoded += 1;
    }
    assert_eq!(decoded, log.message_count());
}
