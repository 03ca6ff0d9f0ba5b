//! Decoding a message's payload to JSON, from the schema the log embeds: protobuf with its
//! FileDescriptorSet (through `prost-reflect`), or JSON as it is.

use std::collections::BTreeMap;

use prost_reflect::{DescriptorPool, DynamicMessage, MessageDescriptor, SerializeOptions};
use serde_json::Value;

/// Decodes the messages of one log, keeping each protobuf schema's descriptor once parsed.
#[derive(Default)]
pub(crate) struct Decoder {
    /// By schema id: the message type, or why the schema can't decode anything.
    descriptors: BTreeMap<u16, Result<MessageDescriptor, String>>,
}

/// How protobuf becomes JSON: the `.proto` field names, every field (defaults too, so a
/// message always has the same keys), and 64-bit integers as numbers.
fn options() -> SerializeOptions {
    SerializeOptions::new()
        .use_proto_field_name(true)
        .skip_default_fields(false)
        .stringify_64_bit_integers(false)
}

impl Decoder {
    /// The payload of `message` as JSON, or why it is not what its channel says.
    pub(crate) fn decode(&mut self, message: &mcap::Message<'_>) -> Result<Value, String> {
        match self.parse(message)? {
            Parsed::Json(value) => Ok(value),
            Parsed::Protobuf(name, decoded) => decoded
                .serialize_with_options(serde_json::value::Serializer, &options())
                .map_err(|e| format!("{name}: {e}")),
        }
    }

    /// Whether `message` decodes with its channel's schema, without building its JSON: what
    /// a comparison that finds two payloads byte-identical still has to know.
    pub(crate) fn check(&mut self, message: &mcap::Message<'_>) -> Result<(), String> {
        self.parse(message).map(|_| ())
    }

    fn parse(&mut self, message: &mcap::Message<'_>) -> Result<Parsed, String> {
        let channel = &message.channel;
        match channel.message_encoding.as_str() {
            "json" => serde_json::from_slice(&message.data)
                .map(Parsed::Json)
                .map_err(|e| format!("not JSON: {e}")),
            "protobuf" => {
                let schema = channel
                    .schema
                    .as_ref()
                    .ok_or("a protobuf channel without a schema")?;
                let descriptor = self
                    .descriptors
                    .entry(schema.id)
                    .or_insert_with(|| descriptor(&schema.name, &schema.data))
                    .clone()?;
                DynamicMessage::decode(descriptor, message.data.as_ref())
                    .map(|m| Parsed::Protobuf(schema.name.clone(), m))
                    .map_err(|e| format!("not a {} message: {e}", schema.name))
            }
            other => Err(format!(
                "message encoding {other:?} is neither json nor protobuf"
            )),
        }
    }
}

/// A payload decoded, before it becomes JSON.
enum Parsed {
    Json(Value),
    /// The schema's name and the message.
    Protobuf(String, DynamicMessage),
}

/// The message type `name` from the FileDescriptorSet `data` (a protobuf channel's schema),
/// or why the schema can't decode anything.
pub(crate) fn descriptor(name: &str, data: &[u8]) -> Result<MessageDescriptor, String> {
    let pool = DescriptorPool::decode(data).map_err(|e| format!("schema {name}: {e}"))?;
    pool.get_message_by_name(name)
        .ok_or_else(|| format!("schema {name}: its descriptor does not define it"))
}
