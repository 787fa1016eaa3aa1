//! The integration tests of `monitor-words`, one test binary (issue 89): each module below was a
//! binary of its own (`tests/<module>.rs`), each linking the whole workspace. One
//! module's tests: `cargo test -p monitor-words --test words -- <module>::`.

mod trend_sentences;
mod trend_words;
