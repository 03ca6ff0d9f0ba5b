//! Two logs compared message by message, so chunking and compression never matter (`ricochet
//! diff A.mcap B.mcap`, and golden checks): the first divergent frame, topic, body and field
//! with both values, then how many messages differ per topic. Equal bytes under the same
//! valid schema are equal messages (their top level checked); only messages that differ are
//! decoded and compared field by field. Both logs are streamed, each read on a thread of its
//! own, one message at a time: memory does not grow with their length.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

use crate::{LogError, LogFile, Messages, RawMessage, escape_controls};

mod fields;
mod render;

use fields::{BodyId, first_in_message, id_of};
pub use render::{render, render_counts, render_head};
use serde::Serialize;
use serde_json::Value;

/// Topics in the order a report names them when several differ at the same time: the
/// plain state first, the drawing last.
const TOPIC_ORDER: [&str; 8] = [
    "/bodies",
    "/contacts",
    "/stats",
    "/events",
    "/tf",
    "/scene",
    "/scene/static",
    "/scene/contacts",
];

/// The first difference found.
#[derive(Serialize, Debug)]
pub struct Divergence {
    /// Topic.
    pub topic: String,
    /// Log time of the message, nanoseconds.
    pub time_ns: u64,
    /// The message's `frame` field, when it has one.
    pub frame: Option<u64>,
    /// The body the difference is in, when it is inside a list of bodies: `id:generation
    /// (name)`, the name found in an earlier message when the differing one lists none.
    pub body: Option<String>,
    /// The body's id while its name is still to be found.
    #[serde(skip)]
    unnamed: Option<BodyId>,
    /// Path of the field inside the message (`bodies[id=4].velocity[0]`).
    pub field: String,
    /// The value in A (JSON), or a note such as `missing`.
    pub a: String,
    /// The value in B.
    pub b: String,
}

/// Per-topic counts.
#[derive(Serialize, Debug, Default)]
pub struct TopicCount {
    /// Messages in A.
    pub messages_a: usize,
    /// Messages in B.
    pub messages_b: usize,
    /// Messages that differ (by position in the topic), plus those only one log has.
    pub differing: usize,
}

/// The whole comparison.
#[derive(Serialize, Debug)]
pub struct Report {
    /// Whether the logs are equal (within the tolerance).
    pub equal: bool,
    /// The absolute tolerance numbers were compared with.
    pub tolerance: f64,
    /// The earliest difference, by log time, then topic order.
    pub first: Option<Divergence>,
    /// Counts per topic.
    pub topics: BTreeMap<String, TopicCount>,
}

/// Whether `d` is reported before `f`: by log time, then topic order.
fn earlier(d: &Divergence, f: &Divergence) -> bool {
    (d.time_ns, rank(&d.topic)) < (f.time_ns, rank(&f.topic))
}

fn rank(topic: &str) -> usize {
    TOPIC_ORDER
        .iter()
        .position(|t| *t == topic)
        .unwrap_or(TOPIC_ORDER.len())
}

/// Why two logs could not be compared (`ricochet diff`'s exit code 2).
#[derive(Debug, thiserror::Error)]
pub enum DiffError {
    /// A log is unreadable, cut short or damaged.
    #[error(transparent)]
    Log(#[from] LogError),
    /// A log is an MCAP file, but not one Ricochet wrote.
    #[error("{0}")]
    Foreign(String),
    /// `--topic` names a topic neither log has.
    #[error("{0}")]
    UnknownTopic(String),
}

/// Opens a log and checks that Ricochet wrote it: its header names `ricochet` as the library
/// and every channel is protobuf with a protobuf schema, or JSON with a JSON Schema (what the
/// comparison decodes).
pub fn open(path: &Path) -> Result<LogFile, DiffError> {
    let log = LogFile::open(path)?;
    let name = path.display();
    let library = log.library();
    if !library.starts_with("ricochet ") {
        return Err(DiffError::Foreign(format!(
            "{name}: not a Ricochet log: it was written by {library:?}, not by `ricochet run`"
        )));
    }
    if let Some(c) = log.channels().find(|c| {
        !matches!(
            (c.message_encoding.as_str(), c.schema_encoding.as_str()),
            ("protobuf", "protobuf") | ("json", "jsonschema")
        )
    }) {
        return Err(DiffError::Foreign(format!(
            "{name}: not a Ricochet log: channel {} has {:?} messages and a {:?} schema, \
             where Ricochet writes protobuf with a protobuf schema",
            c.topic, c.message_encoding, c.schema_encoding
        )));
    }
    Ok(log)
}

/// Compares one topic of two logs, message by message by position: reads both logs' messages
/// on `topic` in log-time order, one at a time, keeping only the count and the first
/// divergence. Equal bytes are equal messages. With an exact comparison, a message is decoded
/// only while it could still be the first divergence of the whole comparison: before this
/// topic's first, and earlier than `best` (the earliest found so far, as time and rank).
fn diff_topic(
    a: &LogFile,
    b: &LogFile,
    topic: &str,
    tol: f64,
    best: Option<(u64, usize)>,
) -> Result<(TopicCount, Option<Divergence>), LogError> {
    let (mut ma, mut mb) = (a.topic_messages(topic)?, b.topic_messages(topic)?);
    let mut count = TopicCount::default();
    let mut first: Option<Divergence> = None;
    loop {
        match (ma.next_raw().transpose()?, mb.next_raw().transpose()?) {
            (Some(x), Some(y)) => {
                count.messages_a += 1;
                count.messages_b += 1;
                if x.bytes() == y.bytes() {
                    // Equal bytes under the same valid schema: equal (see `lockstep`).
                    ma.check(&x)?;
                    mb.check(&y)?;
                    continue;
                }
                let later = best.is_some_and(|b| (x.log_time(), rank(topic)) > b);
                if tol == 0.0 && (first.is_some() || later) {
                    count.differing += 1;
                    continue;
                }
                let (x, y) = (ma.decode(x)?, mb.decode(y)?);
                if let Some(d) = first_in_message(topic, &x, &y, tol) {
                    count.differing += 1;
                    first.get_or_insert(d);
                }
            }
            (None, None) => break,
            // One log has more messages on the topic: the first extra one is the divergence
            // when nothing differed before it, then the rest are counted.
            (extra, rest) => {
                let (mine, other, in_a) = match (extra, rest) {
                    (Some(m), None) => (m, &mut ma, true),
                    (None, Some(m)) => (m, &mut mb, false),
                    _ => unreachable!("both None and both Some are matched above"),
                };
                let mut n = 1;
                while other.next_raw().transpose()?.is_some() {
                    n += 1;
                }
                if in_a {
                    count.messages_a += n;
                } else {
                    count.messages_b += n;
                }
                count.differing += n;
                let time_ns = mine.log_time();
                // Its frame, from a message small enough to decode cheaply.
                let frame = if mine.bytes().len() <= 1 << 16 {
                    let decoded = if in_a {
                        ma.decode(mine)
                    } else {
                        mb.decode(mine)
                    };
                    decoded?.data.get("frame").and_then(Value::as_u64)
                } else {
                    None
                };
                first.get_or_insert(Divergence {
                    topic: topic.to_owned(),
                    time_ns,
                    frame,
                    body: None,
                    unnamed: None,
                    field: "message count".to_owned(),
                    a: count.messages_a.to_string(),
                    b: count.messages_b.to_string(),
                });
                break;
            }
        }
    }
    Ok((count, first))
}

/// Compares two logs in one pass, message by message in file order, while both logs hold the
/// same topics at the same times in the same order (two runs of one scenario do, unless
/// they diverge in which messages they send). Equal payloads are compared byte for byte,
/// without decoding; others are decoded and compared field by field. `None` as soon as the
/// two logs' messages stop pairing up: [`diff_files`] then compares topic by topic.
fn lockstep(
    a: &LogFile,
    b: &LogFile,
    tol: f64,
    topics: &BTreeSet<&str>,
    announce: &mut Announce<'_>,
) -> Result<Lockstep, LogError> {
    let (mut ma, mut mb) = (a.messages()?, b.messages()?);
    let mut counts: BTreeMap<String, TopicCount> = topics
        .iter()
        .map(|t| ((*t).to_owned(), TopicCount::default()))
        .collect();
    let mut first: Option<Divergence> = None;
    // The pairs of one time whose bytes differ, decoded only when the time is over, best
    // ranked first: the first divergence is the best ranked topic that differs at the
    // earliest time, and the others (a whole `/scene`, say) need not be decoded.
    let mut group: Vec<(usize, RawMessage, RawMessage)> = Vec::new();
    let resolve = |group: &mut Vec<(usize, RawMessage, RawMessage)>,
                   counts: &mut BTreeMap<String, TopicCount>,
                   first: &mut Option<Divergence>,
                   ma: &mut Messages,
                   mb: &mut Messages|
     -> Result<(), LogError> {
        group.sort_by_key(|(rank, ..)| *rank);
        for (_, x, y) in group.drain(..) {
            let topic = x.topic().to_owned();
            let count = counts.entry(topic.clone()).or_default();
            if tol == 0.0 && first.is_some() {
                // Exact comparison: the writer's encoding is canonical, so differing bytes
                // are a differing message; past the first divergence, no need to decode.
                count.differing += 1;
                continue;
            }
            let (x, y) = (ma.decode(x)?, mb.decode(y)?);
            if let Some(d) = first_in_message(&topic, &x, &y, tol) {
                count.differing += 1;
                if first.as_ref().is_none_or(|f| earlier(&d, f)) {
                    *first = Some(d);
                }
            }
        }
        Ok(())
    };
    loop {
        let (x, y) = match (ma.next_raw().transpose()?, mb.next_raw().transpose()?) {
            (None, None) => break,
            (Some(x), Some(y)) if x.topic() == y.topic() && x.log_time() == y.log_time() => (x, y),
            _ => return Ok(Lockstep::Broken(first)),
        };
        let Some(count) = counts.get_mut(x.topic()) else {
            return Ok(Lockstep::Broken(first));
        };
        count.messages_a += 1;
        count.messages_b += 1;
        if group
            .first()
            .is_some_and(|(_, g, _)| g.log_time() != x.log_time())
        {
            let found = first.is_some();
            resolve(&mut group, &mut counts, &mut first, &mut ma, &mut mb)?;
            // The first difference of the earliest time that has one is the first: nothing
            // read later can come before it, so it is told before the counts are done.
            if !found && let Some(d) = first.as_mut() {
                announce(d)?;
            }
        }
        if x.bytes() != y.bytes() {
            group.push((rank(x.topic()), x, y));
        } else {
            // Equal bytes under the same valid schema (checked once per channel, when the
            // logs were opened and by `schema_difference`) are equal messages: only their
            // top level is checked, not decoded whole (see `Messages::check`).
            ma.check(&x)?;
            mb.check(&y)?;
        }
    }
    resolve(&mut group, &mut counts, &mut first, &mut ma, &mut mb)?;
    Ok(Lockstep::Done(Report {
        equal: first.is_none(),
        tolerance: tol,
        first,
        topics: counts,
    }))
}

/// The report on two logs with the same channels and the same bytes up to their summaries
/// ([`LogFile::same_data`]): equal, their messages counted (and checked) by reading one.
fn same_data(
    a: &LogFile,
    tol: f64,
    topics: &BTreeSet<&str>,
    only: Option<&str>,
) -> Result<Report, LogError> {
    let mut counts: BTreeMap<String, TopicCount> = topics
        .iter()
        .filter(|t| only.is_none_or(|o| o == **t))
        .map(|t| ((*t).to_owned(), TopicCount::default()))
        .collect();
    let mut messages = a.messages()?;
    while let Some(x) = messages.next_raw().transpose()? {
        if let Some(count) = counts.get_mut(x.topic()) {
            count.messages_a += 1;
            count.messages_b += 1;
        }
        messages.check(&x)?;
    }
    Ok(Report {
        equal: true,
        tolerance: tol,
        first: None,
        topics: counts,
    })
}

/// How a one-pass comparison ended.
enum Lockstep {
    /// Both logs were read to the end.
    Done(Report),
    /// Their messages stopped pairing up; the first difference before that, if any, is the
    /// first of the whole comparison (and was announced).
    Broken(Option<Divergence>),
}

/// What is told the first difference as soon as it is known: it names the body, then hands
/// it on (see [`diff_files_with`]).
type Announce<'f> = dyn FnMut(&mut Divergence) -> Result<(), LogError> + 'f;

/// How a topic's channels are encoded in a log: message encoding, schema name, schema
/// encoding and schema bytes of each, in channel id order.
fn encodings<'a>(log: &'a LogFile, topic: &str) -> Vec<(&'a str, &'a str, &'a str, &'a [u8])> {
    log.channels()
        .filter(|c| c.topic == topic)
        .map(|c| {
            (
                c.message_encoding.as_str(),
                c.schema_name.as_str(),
                c.schema_encoding.as_str(),
                c.schema_data.as_slice(),
            )
        })
        .collect()
}

/// The first topic, in report order, whose schema differs between the two logs (its name,
/// encoding or bytes): equal bytes read through different schemas are different messages,
/// so this is a difference before any message's.
fn schema_difference(a: &LogFile, b: &LogFile) -> Option<Divergence> {
    let both: BTreeSet<&str> = a
        .channels()
        .map(|c| c.topic.as_str())
        .filter(|t| b.channels().any(|c| c.topic == *t))
        .collect();
    let mut ordered: Vec<&str> = both.into_iter().collect();
    ordered.sort_by_key(|t| (rank(t), *t));
    ordered.into_iter().find_map(|topic| {
        let (ea, eb) = (encodings(a, topic), encodings(b, topic));
        if ea == eb {
            return None;
        }
        let describe = |e: &[(&str, &str, &str, &[u8])], other: &[(&str, &str, &str, &[u8])]| {
            let parts: Vec<String> = e
                .iter()
                .enumerate()
                .map(|(i, (message, name, encoding, data))| {
                    let mut text = format!(
                        "{} ({message} messages, {encoding} schema of {} bytes)",
                        escape_controls(name),
                        data.len()
                    );
                    // Same name and size: say where the bytes part.
                    if let Some((.., o)) = other.get(i)
                        && o.len() == data.len()
                        && let Some(at) = data.iter().zip(o.iter()).position(|(x, y)| x != y)
                    {
                        text += &format!(", differing from byte {at}");
                    }
                    text
                })
                .collect();
            parts.join("; ")
        };
        Some(Divergence {
            topic: topic.to_owned(),
            time_ns: 0,
            frame: None,
            body: None,
            unnamed: None,
            field: "schema".to_owned(),
            a: describe(&ea, &eb),
            b: describe(&eb, &ea),
        })
    })
}

/// Compares two logs, streaming them topic by topic: memory does not grow with their length.
/// A schema that differs between them is the first difference. Schemas are checked once per
/// channel (when a log is opened, and against the other log's); a message whose bytes are
/// equal in both logs is then an equal message, its top level checked but not decoded; a
/// message that differs is decoded and compared field by field.
pub fn diff_files(
    a: &LogFile,
    b: &LogFile,
    tol: f64,
    only: Option<&str>,
) -> Result<Report, DiffError> {
    diff_files_with(a, b, tol, only, &mut |_| {})
}

/// [`diff_files`], telling `on_first` the first difference as soon as it is known (the same
/// one the report gives), before the counts are done: at once for a schema, and when the
/// logs are read in one pass, once the log time it is at is over. At most once; never when
/// the logs are equal or the first is only known at the end.
pub fn diff_files_with(
    a: &LogFile,
    b: &LogFile,
    tol: f64,
    only: Option<&str>,
    on_first: &mut dyn FnMut(&Divergence),
) -> Result<Report, DiffError> {
    let schema = schema_difference(a, b).filter(|d| only.is_none_or(|t| t == d.topic));
    let mut told = false;
    if let Some(d) = &schema {
        on_first(d);
        told = true;
    }
    let mut announce = |d: &mut Divergence| -> Result<(), LogError> {
        if !told {
            name_body(a, b, d)?;
            on_first(d);
            told = true;
        }
        Ok(())
    };
    let mut report = diff_messages(a, b, tol, only, &mut announce)?;
    if let Some(d) = schema {
        report.equal = false;
        report.first = Some(d);
    }
    if let Some(d) = report.first.as_mut() {
        name_body(a, b, d)?;
    }
    Ok(report)
}

/// Names the body of a `/bodies` divergence, from either log (once: its id is then taken).
fn name_body(a: &LogFile, b: &LogFile, d: &mut Divergence) -> Result<(), LogError> {
    if d.topic == "/bodies"
        && let Some(id) = d.unnamed.take()
    {
        let name = match name_of(a, id, d.time_ns)? {
            Some(n) => Some(n),
            None => name_of(b, id, d.time_ns)?,
        };
        if let Some(name) = name {
            d.body = Some(format!("{id} ({})", escape_controls(&name)));
        }
    }
    Ok(())
}

/// The name of body `id` in `log`: a `/bodies` message lists a body's name when the body
/// appears (and at keyframes), not in the deltas between, so it is found in the first message
/// up to `until_ns` (the divergence's time) that lists it with one. Reads one message at a
/// time, and usually few: a body of the initial scene is named in the first message.
fn name_of(log: &LogFile, id: BodyId, until_ns: u64) -> Result<Option<String>, LogError> {
    let mut messages = log.topic_messages("/bodies")?;
    while let Some(raw) = messages.next_raw().transpose()? {
        if raw.log_time() > until_ns {
            break;
        }
        let message = messages.decode(raw)?;
        let listed = message.data.get("bodies").and_then(Value::as_array);
        let name = listed
            .into_iter()
            .flatten()
            .filter(|b| id_of(b) == Some(id))
            .find_map(|b| b.get("name").and_then(Value::as_str));
        if let Some(name) = name {
            return Ok(Some(name.to_owned()));
        }
    }
    Ok(None)
}

/// The messages of two logs compared, in one pass or topic by topic.
fn diff_messages(
    a: &LogFile,
    b: &LogFile,
    tol: f64,
    only: Option<&str>,
    announce: &mut Announce<'_>,
) -> Result<Report, DiffError> {
    let present: BTreeSet<&str> = a
        .channels()
        .chain(b.channels())
        .map(|c| c.topic.as_str())
        .collect();
    if let Some(t) = only
        && !present.contains(t)
    {
        let list: Vec<&str> = present.iter().copied().collect();
        let slashed = format!("/{t}");
        let hint = if present.contains(slashed.as_str()) {
            format!(" (did you mean {slashed}?)")
        } else {
            String::new()
        };
        return Err(DiffError::UnknownTopic(format!(
            "--topic {}: neither log has that topic{hint}; they have: {}",
            escape_controls(t),
            list.join(", ")
        )));
    }
    // The topics with messages in either log, as a table of counts lists them.
    let with_messages: BTreeSet<&str> = a
        .channels()
        .chain(b.channels())
        .filter(|c| c.messages > 0 || only == Some(c.topic.as_str()))
        .map(|c| c.topic.as_str())
        .collect();
    if a.same_data(b)? {
        return Ok(same_data(a, tol, &with_messages, only)?);
    }
    // The first difference found in one pass before the logs stopped pairing up: the first
    // of all (both logs are the same messages up to there), already announced.
    let mut first: Option<Divergence> = None;
    if only.is_none() {
        match lockstep(a, b, tol, &with_messages, announce)? {
            Lockstep::Done(report) => return Ok(report),
            Lockstep::Broken(found) => first = found,
        }
    }
    let told = first.is_some();
    let mut topics = BTreeMap::new();
    // Best ranked first: a later topic's messages need no decoding once they can't be first.
    let mut ordered: Vec<&str> = with_messages.into_iter().collect();
    ordered.sort_by_key(|t| (rank(t), *t));
    for topic in ordered {
        if only.is_some_and(|t| t != topic) {
            continue;
        }
        let best = first.as_ref().map(|f| (f.time_ns, rank(&f.topic)));
        let (count, topic_first) = diff_topic(a, b, topic, tol, best)?;
        if let Some(d) = topic_first
            && !told
            && first.as_ref().is_none_or(|f| earlier(&d, f))
        {
            first = Some(d);
        }
        topics.insert(topic.to_owned(), count);
    }
    Ok(Report {
        equal: first.is_none(),
        tolerance: tol,
        first,
        topics,
    })
}
