//! Lines and columns of positions in the SVG text being read, in time linear in the file.
//!
//! `roxmltree` computes a position's line by scanning the text from its start, so naming the
//! line of each of many elements (a warning for each of 64,000 paths) would take time
//! quadratic in the file. While a [`LineIndex`] is alive, the positions of its document are
//! looked up in the starts of its lines instead.

use std::cell::RefCell;

use roxmltree::Document;

/// The document whose lines are indexed: the address and length of its text, and the byte
/// offset where each line starts.
struct Indexed {
    text: usize,
    len: usize,
    starts: Vec<usize>,
}

thread_local! {
    static INDEXED: RefCell<Option<Indexed>> = const { RefCell::new(None) };
}

/// The starts of the lines of one document, in use for [`line_column`] on this thread until
/// it is dropped (the document outlives it, so its text cannot be mistaken for another's).
pub(super) struct LineIndex<'a> {
    _doc: std::marker::PhantomData<&'a Document<'a>>,
}

impl<'a> LineIndex<'a> {
    /// Indexes the lines of `doc`'s text.
    pub(super) fn new(doc: &'a Document<'a>) -> Self {
        let text = doc.input_text();
        let starts = std::iter::once(0)
            .chain(
                text.bytes()
                    .enumerate()
                    .filter(|&(_, b)| b == b'\n')
                    .map(|(i, _)| i + 1),
            )
            .collect();
        let indexed = Indexed {
            text: text.as_ptr() as usize,
            len: text.len(),
            starts,
        };
        INDEXED.with(|slot| *slot.borrow_mut() = Some(indexed));
        LineIndex {
            _doc: std::marker::PhantomData,
        }
    }
}

impl Drop for LineIndex<'_> {
    fn drop(&mut self) {
        INDEXED.with(|slot| *slot.borrow_mut() = None);
    }
}

/// The line and column (1-based, the column in characters, lines ended by `\n`) of byte
/// `pos` of `doc`'s text, as `roxmltree`'s `text_pos_at` counts them.
pub(super) fn line_column(doc: &Document, pos: usize) -> (usize, usize) {
    let text = doc.input_text();
    let line_start = INDEXED.with(|slot| {
        let slot = slot.borrow();
        let indexed = slot
            .as_ref()
            .filter(|i| i.text == text.as_ptr() as usize && i.len == text.len())?;
        let line = indexed.starts.partition_point(|&s| s <= pos);
        Some((line, indexed.starts[line - 1]))
    });
    match line_start {
        Some((line, start)) => {
            let column = text.get(start..pos).map_or(0, |s| s.chars().count()) + 1;
            (line, column)
        }
        None => {
            let p = doc.text_pos_at(pos);
            (p.row as usize, p.col as usize)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every element's line and column is the one `roxmltree` gives, with and without the
    /// index (multi-byte characters, CRLF line ends, elements on one line).
    #[test]
    fn positions_match_roxmltree() {
        let text = "<svg xmlns='http://www.w3.org/2000/svg'>\r\n<!-- é ✓ -->\n  <g><rect id='é'/> <rect/>\n</g>\n\n\t<path d=''/></svg>";
        let doc = Document::parse(text).unwrap();
        let expected: Vec<(usize, usize)> = doc
            .descendants()
            .map(|n| {
                let p = doc.text_pos_at(n.range().start);
                (p.row as usize, p.col as usize)
            })
            .collect();
        let positions = || -> Vec<(usize, usize)> {
            doc.descendants()
                .map(|n| line_column(&doc, n.range().start))
                .collect()
        };
        assert_eq!(positions(), expected);
        let index = LineIndex::new(&doc);
        assert_eq!(positions(), expected);
        drop(index);
        assert!(INDEXED.with(|slot| slot.borrow().is_none()));
        assert_eq!(positions(), expected);
    }
}
