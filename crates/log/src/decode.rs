//! Decoding a message's payload to JSON, from the schema the log embeds: protobuf with its
//! FileDescriptorSet (through `prost-reflect`), or JSON as it is.

use std::collections::BTreeMap;

use prost::encoding::{DecodeContext, WireType, decode_key, decode_varint, skip_field};
use prost_reflect::{DescriptorPool, DynamicMessage, Kind, MessageDescriptor, SerializeOptions};
use serde::de::IgnoredAny;
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

    /// Whether the top level of `message` decodes with its channel's schema: what a
    /// comparison that finds two payloads byte-identical checks, instead of decoding them
    /// whole (equal bytes under the same valid schema are equal messages, and a whole
    /// 10,000-body `/scene` takes some 30 ms to decode). See [`check_top_level`].
    pub(crate) fn check(&mut self, message: &mcap::Message<'_>) -> Result<(), String> {
        let channel = &message.channel;
        match channel.message_encoding.as_str() {
            "json" => serde_json::from_slice::<IgnoredAny>(&message.data)
                .map(|_| ())
                .map_err(|e| format!("not JSON: {e}")),
            "protobuf" => {
                let (name, descriptor) = self.descriptor(message)?;
                check_top_level(&descriptor, &message.data)
                    .map_err(|e| format!("not a {name} message: {e}"))
            }
            other => Err(format!(
                "message encoding {other:?} is neither json nor protobuf"
            )),
        }
    }

    /// The schema's name and message type of a protobuf message's channel.
    fn descriptor<'m>(
        &mut self,
        message: &'m mcap::Message<'_>,
    ) -> Result<(&'m str, MessageDescriptor), String> {
        let schema = message
            .channel
            .schema
            .as_ref()
            .ok_or("a protobuf channel without a schema")?;
        let descriptor = self
            .descriptors
            .entry(schema.id)
            .or_insert_with(|| descriptor(&schema.name, &schema.data))
            .clone()?;
        Ok((&schema.name, descriptor))
    }

    fn parse(&mut self, message: &mcap::Message<'_>) -> Result<Parsed, String> {
        let channel = &message.channel;
        match channel.message_encoding.as_str() {
            "json" => serde_json::from_slice(&message.data)
                .map(Parsed::Json)
                .map_err(|e| format!("not JSON: {e}")),
            "protobuf" => {
                let (name, descriptor) = self.descriptor(message)?;
                DynamicMessage::decode(descriptor, message.data.as_ref())
                    .map(|m| Parsed::Protobuf(name.to_owned(), m))
                    .map_err(|e| format!("not a {name} message: {e}"))
            }
            other => Err(format!(
                "message encoding {other:?} is neither json nor protobuf"
            )),
        }
    }
}

/// Checks the top level of a protobuf payload against its message type, as a whole decode
/// would: every key, varint and length is well formed and inside the payload, and every
/// field that is not a nested message (numbers, strings, enums, packed lists, unknown
/// fields) decodes as its type says. A nested message (a `/scene` entity, a `/bodies` body)
/// is only checked to be a length-delimited field inside the payload: its own bytes are not
/// walked, which is what keeps this cheap (a few microseconds for a 1.5 MB `/scene`).
pub(crate) fn check_top_level(descriptor: &MessageDescriptor, data: &[u8]) -> Result<(), String> {
    let mut buf = data;
    // The other fields' bytes, decoded together at the end (small: frame numbers, times).
    let mut rest = Vec::new();
    // Repeated fields come one after another: the last field number's answer is kept.
    let mut last: Option<(u32, bool)> = None;
    while !buf.is_empty() {
        let start = data.len() - buf.len();
        let (number, wire_type) = decode_key(&mut buf).map_err(|e| e.to_string())?;
        let nested = match last {
            Some((n, nested)) if n == number => nested,
            _ => {
                let nested = descriptor.get_field(number).is_some_and(|f| {
                    matches!(f.kind(), Kind::Message(_)) && !f.is_group() && !f.is_map()
                });
                last = Some((number, nested));
                nested
            }
        };
        if nested && wire_type == WireType::LengthDelimited {
            let len = decode_varint(&mut buf).map_err(|e| e.to_string())?;
            let len = usize::try_from(len)
                .ok()
                .filter(|l| *l <= buf.len())
                .ok_or("failed to decode Protobuf message: buffer underflow")?;
            buf = &buf[len..];
        } else {
            skip_field(wire_type, number, &mut buf, DecodeContext::default())
                .map_err(|e| e.to_string())?;
            rest.extend_from_slice(&data[start..data.len() - buf.len()]);
        }
    }
    DynamicMessage::decode(descriptor.clone(), rest.as_slice())
        .map(|_| ())
        .map_err(|e| e.to_string())
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::messages::RICOCHET_DESCRIPTOR;

    fn message(name: &str) -> MessageDescriptor {
        descriptor(name, RICOCHET_DESCRIPTOR).unwrap()
    }

    #[test]
    fn the_top_level_check_agrees_with_a_whole_decode_on_top_level_damage() {
        let (bodies, stats) = (message("ricochet.Bodies"), message("ricochet.Stats"));
        // (type, payload, sound): protobuf's wire format by hand, field number << 3 | type.
        let cases: [(&MessageDescriptor, &[u8], bool); 9] = [
            (&bodies, b"", true),
            // frame 5, a body with id 1, gravity packed as one double.
            (
                &bodies,
                b"\x08\x05\x22\x02\x08\x01\x3a\x08\0\0\0\0\0\0\xf0\x3f",
                true,
            ),
            // An unknown field (99, a varint) is kept, not an error.
            (&bodies, b"\x98\x06\x01", true),
            // frame as a length-delimited field: the wrong wire type.
            (&bodies, b"\x0a\x01\x00", false),
            // A varint cut short.
            (&bodies, b"\x08\x80", false),
            // A body longer than what is left.
            (&bodies, b"\x22\x05\x08", false),
            // Wire type 7 does not exist.
            (&bodies, b"\x0f", false),
            // broad_phase, a string, that is not UTF-8.
            (&stats, b"\x1a\x01\xff", false),
            // frame as a length running past the end.
            (&stats, b"\x0a\x7f\x01", false),
        ];
        for (descriptor, payload, sound) in cases {
            let whole = DynamicMessage::decode(descriptor.clone(), payload);
            assert_eq!(whole.is_ok(), sound, "{payload:?}: {whole:?}");
            let top = check_top_level(descriptor, payload);
            assert_eq!(top.is_ok(), sound, "{payload:?}: {top:?}");
        }
    }

    #[test]
    fn the_top_level_check_does_not_walk_nested_messages() {
        // A body (field 4, 3 bytes) whose own field 1 runs past its end: a whole decode
        // finds it, the top-level check only sees a sound length-delimited field.
        let payload = b"\x22\x03\x0a\x7f\x01";
        let bodies = message("ricochet.Bodies");
        assert!(DynamicMessage::decode(bodies.clone(), &payload[..]).is_err());
        assert_eq!(check_top_level(&bodies, payload), Ok(()));
    }
}
