//! The objects of a PDF file as lopdf reads them: references followed within a depth, values
//! checked, and errors that name the object they are in.

use lopdf::{Dictionary, Document, Object, ObjectId, Stream};

use crate::error::{Error, ErrorKind};

/// The deepest chain of references followed (a loop is refused at this depth).
const MAX_REFERENCE_DEPTH: usize = 32;

/// The name of an object in messages: `object 12` (with its generation when not 0).
pub(crate) fn object_name(id: ObjectId) -> String {
    match id.1 {
        0 => format!("object {}", id.0),
        g => format!("object {} {g}", id.0),
    }
}

/// An error about `what`.
pub(crate) fn invalid(what: impl Into<String>, message: impl Into<String>) -> Error {
    ErrorKind::Invalid {
        what: what.into(),
        message: message.into(),
    }
    .into()
}

/// The file's objects.
#[derive(Clone, Copy)]
pub(crate) struct Objects<'a> {
    pub doc: &'a Document,
}

impl<'a> Objects<'a> {
    /// `object` with its references followed, and the id of the last one (none when `object`
    /// is direct). `what` names it in errors.
    pub fn resolve(
        &self,
        object: &'a Object,
        what: &str,
    ) -> Result<(&'a Object, Option<ObjectId>), Error> {
        let mut current = object;
        let mut id = None;
        let mut seen: Vec<ObjectId> = Vec::new();
        while let Object::Reference(target) = current {
            if seen.contains(target) || seen.len() >= MAX_REFERENCE_DEPTH {
                return Err(invalid(
                    what,
                    format!(
                        "its references loop or run deeper than {MAX_REFERENCE_DEPTH} ({})",
                        object_name(*target)
                    ),
                ));
            }
            seen.push(*target);
            id = Some(*target);
            current = self.doc.objects.get(target).ok_or_else(|| {
                invalid(
                    what,
                    format!(
                        "it refers to {}, which the file lacks",
                        object_name(*target)
                    ),
                )
            })?;
        }
        Ok((current, id))
    }

    /// The entry `key` of `dict`, references followed; `None` when absent or null.
    pub fn get(
        &self,
        dict: &'a Dictionary,
        key: &[u8],
        what: &str,
    ) -> Result<Option<&'a Object>, Error> {
        match dict.get(key) {
            Ok(o) => {
                let (o, _) =
                    self.resolve(o, &format!("{what} /{}", String::from_utf8_lossy(key)))?;
                Ok((!matches!(o, Object::Null)).then_some(o))
            }
            Err(_) => Ok(None),
        }
    }

    /// The dictionary of `object` (a stream's dictionary for a stream).
    pub fn dict(&self, object: &'a Object, what: &str) -> Result<&'a Dictionary, Error> {
        match self.resolve(object, what)?.0 {
            Object::Dictionary(d) => Ok(d),
            Object::Stream(s) => Ok(&s.dict),
            other => Err(invalid(
                what,
                format!("expected a dictionary, found {}", other.enum_variant()),
            )),
        }
    }

    /// The stream `object` refers to.
    pub fn stream(&self, object: &'a Object, what: &str) -> Result<&'a Stream, Error> {
        match self.resolve(object, what)?.0 {
            Object::Stream(s) => Ok(s),
            other => Err(invalid(
                what,
                format!("expected a stream, found {}", other.enum_variant()),
            )),
        }
    }

    /// The number `object` is (or refers to), finite.
    pub fn number(&self, object: &'a Object, what: &str) -> Result<f64, Error> {
        number(self.resolve(object, what)?.0, what)
    }

    /// The numbers of the array `object` is (or refers to).
    pub fn numbers(&self, object: &'a Object, what: &str) -> Result<Vec<f64>, Error> {
        match self.resolve(object, what)?.0 {
            Object::Array(items) => items.iter().map(|o| self.number(o, what)).collect(),
            other => Err(invalid(
                what,
                format!(
                    "expected an array of numbers, found {}",
                    other.enum_variant()
                ),
            )),
        }
    }

    /// The name `object` is (or refers to).
    pub fn name(&self, object: &'a Object, what: &str) -> Result<&'a [u8], Error> {
        match self.resolve(object, what)?.0 {
            Object::Name(n) => Ok(n),
            other => Err(invalid(
                what,
                format!("expected a name, found {}", other.enum_variant()),
            )),
        }
    }

    /// The decoded data of `stream`, at most `max_bytes` of it.
    pub fn stream_data(
        &self,
        stream: &Stream,
        what: &str,
        max_bytes: u64,
    ) -> Result<Vec<u8>, Error> {
        let limit = usize::try_from(max_bytes).unwrap_or(usize::MAX);
        stream
            .get_plain_content_with_limit(limit)
            .map_err(|e| invalid(what, format!("its stream cannot be decoded: {e}")))
    }
}

/// The number `object` is, finite.
pub(crate) fn number(object: &Object, what: &str) -> Result<f64, Error> {
    let value = match object {
        Object::Integer(i) => *i as f64,
        Object::Real(r) => f64::from(*r),
        other => {
            return Err(invalid(
                what,
                format!("expected a number, found {}", other.enum_variant()),
            ))
        }
    };
    if value.is_finite() {
        Ok(value)
    } else {
        Err(ErrorKind::NotFinite {
            what: what.into(),
            value: value.to_string(),
        }
        .into())
    }
}
