// The editor with audio running: opened and closed again and again while the audio thread
// plays (no allocation or lock on it, counted by the host tests' audit counter), live views
// showing the note, and the layout at 100 % and 200 % and across window sizes. Needs an X
// display: CTest runs it under xvfb-run.
#include <gtest/gtest.h>

#include <juce_audio_processors/juce_audio_processors.h>
#include <juce_gui_basics/juce_gui_basics.h>

#include <atomic>
#include <thread>

#ifndef ROSIN_EDITOR_ASAN // AddressSanitizer owns malloc: no audit counter in that build
#include "AuditCounter.h"
#endif
#include "RosinEditor.h"
#include "RosinProcessor.h"

using namespace rosin;

namespace {

/// Runs processBlock in real time on its own thread, like a sound card would.
class AudioThread {
public:
    explicit AudioThread(plugin::RosinProcessor& p, bool autoplay = true, double fs = 48000.0, int block = 256)
        : p_(p), block_(block), autoplay_(autoplay)
    {
        p_.setRateAndBufferSizeDetails(fs, block);
        p_.prepareToPlay(fs, block);
        buffer_.setSize(2, block);
        midi_.ensureSize(4096);
        thread_ = std::thread([this, fs] {
            auto next = std::chrono::steady_clock::now();
            const auto period = std::chrono::microseconds(static_cast<long>(1e6 * block_ / fs));
            while (!stop_) {
                midi_.clear();
                const int b = autoplay_ ? blocks_.load() : 1;
                if (b % 400 == 0) midi_.addEvent(juce::MidiMessage::noteOn(1, 50 + (b / 400) % 12, 0.8f), 17);
                if (b % 400 == 300) midi_.addEvent(juce::MidiMessage::noteOff(1, 50 + (b / 400) % 12), 3);
                if (b % 50 == 7) midi_.addEvent(juce::MidiMessage::controllerEvent(1, 2, (b / 50 * 13) % 128), 100);
                p_.processBlock(buffer_, midi_);
                blocks_++;
                next += period;
                std::this_thread::sleep_until(next);
            }
        });
    }
    ~AudioThread()
    {
        stop_ = true;
        thread_.join();
    }
    int blocks() const { return blocks_.load(); }

private:
    plugin::RosinProcessor& p_;
    int block_;
    bool autoplay_;
    juce::AudioBuffer<float> buffer_;
    juce::MidiBuffer midi_;
    std::atomic<bool> stop_{false};
    std::atomic<int> blocks_{0};
    std::thread thread_;
};

} // namespace
namespace juce { bool dispatchNextMessageOnSystemQueue(bool returnIfNoPendingMessages); } // JUCE's Linux message loop
namespace {

/// Runs the message loop for `ms` (timers, repaints, async updates), as an application would.
void pump(int ms)
{
    const auto end = juce::Time::getMillisecondCounter() + static_cast<juce::uint32>(ms);
    while (juce::Time::getMillisecondCounter() < end)
        if (!juce::dispatchNextMessageOnSystemQueue(true)) juce::Thread::sleep(2);
}

/// Pixels in `area` that differ from its most common colour.
int busyPixels(const juce::Image& img, juce::Rectangle<int> area)
{
    const juce::Colour ref = img.getPixelAt(area.getX() + 2, area.getY() + 2);
    int n = 0;
    for (int y = area.getY(); y < area.getBottom(); y += 2)
        for (int x = area.getX(); x < area.getRight(); x += 2)
            if (img.getPixelAt(x, y) != ref) ++n;
    return n;
}

juce::File artefacts()
{
    auto dir = juce::File(ROSIN_TEST_ARTEFACTS);
    dir.createDirectory();
    return dir;
}

struct Gui {
    juce::ScopedJuceInitialiser_GUI init;
};

} // namespace

TEST(Editor, OpenAndCloseRepeatedlyWhileAudioRunsWithoutAllocatingOrLockingOnTheAudioThread)
{
    Gui gui;
#ifndef ROSIN_EDITOR_ASAN
    ASSERT_TRUE(host::audit::selfTest());
#endif
    plugin::RosinProcessor processor;
    AudioThread audio(processor);
    pump(300);
#ifndef ROSIN_EDITOR_ASAN
    host::audit::reset();
#endif
    unsigned long long framesSeen = 0;
    for (int i = 0; i < 25; ++i) {
        std::unique_ptr<juce::AudioProcessorEditor> editor(processor.createEditorIfNeeded());
        ASSERT_NE(editor, nullptr);
        editor->setSize(900 + 40 * (i % 5), 600 + 30 * (i % 4)); // resizing while it plays, too
        pump(60 + 20 * (i % 3));
        framesSeen += static_cast<ui::RosinEditor*>(editor.get())->views().framesSeen();
        processor.editorBeingDeleted(editor.get());
        editor.reset();
        pump(10);
    }
#ifndef ROSIN_EDITOR_ASAN
    const auto counts = host::audit::read();
    EXPECT_TRUE(counts.scopeSeen);
    EXPECT_EQ(counts.plugin.allocations, 0u);
    EXPECT_EQ(counts.plugin.frees, 0u);
    EXPECT_EQ(counts.plugin.locks, 0u);
    EXPECT_EQ(counts.plugin.waits, 0u);
    EXPECT_EQ(counts.plugin.blocking, 0u);
#endif
    EXPECT_GT(audio.blocks(), 200);
    EXPECT_GT(framesSeen, 48000u) << "the views received the sounding notes";
    EXPECT_FALSE(processor.viewRing().listening()) << "a closed window stops the tap";
}

TEST(Editor, LiveViewsShowTheNoteAndTheScopeMoves)
{
    Gui gui;
    plugin::RosinProcessor processor;
    AudioThread audio(processor, false);
    std::unique_ptr<juce::AudioProcessorEditor> editor(processor.createEditorIfNeeded());
    auto& e = *static_cast<ui::RosinEditor*>(editor.get());
    e.setSize(ui::RosinEditor::defaultWidth, ui::RosinEditor::defaultHeight);
    // A note from the window's own keyboard (the path a Standalone user clicks).
    for (int waited = 0; waited < 20000 && !e.views().mapReady(); waited += 100) pump(100);
    ASSERT_TRUE(e.views().mapReady()) << "the playability map never finished";
    e.keyboardState().noteOn(1, 57, 0.9f); // A3 on the cello: the open A string
    pump(1500);
    e.views().refreshNow();
    const juce::Image a = e.createComponentSnapshot(e.getLocalBounds());
    pump(250);
    e.views().refreshNow();
    const juce::Image b = e.createComponentSnapshot(e.getLocalBounds());
    e.keyboardState().noteOff(1, 57, 0.0f);
    juce::PNGImageFormat png;
    juce::FileOutputStream out(artefacts().getChildFile("editor-100.png"));
    out.setPosition(0);
    out.truncate();
    ASSERT_TRUE(png.writeImageToStream(a, out));

    const auto views = e.views().getBoundsInParent();
    const int w = views.getWidth() / 2, h = views.getHeight() / 2;
    const std::array<juce::Rectangle<int>, 4> quads{juce::Rectangle<int>(views.getX(), views.getY(), w, h).reduced(w / 8, h / 6),
                                                    juce::Rectangle<int>(views.getX() + w, views.getY(), w, h).reduced(w / 8, h / 6),
                                                    juce::Rectangle<int>(views.getX(), views.getY() + h, w, h).reduced(w / 8, h / 6),
                                                    juce::Rectangle<int>(views.getX() + w, views.getY() + h, w, h).reduced(w / 8, h / 6)};
    for (int q = 0; q < 4; ++q) EXPECT_GT(busyPixels(a, quads[static_cast<std::size_t>(q)]), 400) << "view " << q << " is blank";
    int moved = 0;
    for (int y = quads[2].getY(); y < quads[2].getBottom(); ++y) // the temperature trace scrolls
        for (int x = quads[2].getX(); x < quads[2].getRight(); ++x) moved += a.getPixelAt(x, y) != b.getPixelAt(x, y);
    EXPECT_GT(moved, 100) << "the temperature trace did not move";
    const auto g = e.views().history().gesture();
    EXPECT_NEAR(g.frequency, 220.0, 3.0);
    EXPECT_GT(g.force, 0.5);
    processor.editorBeingDeleted(editor.get());
}

TEST(Editor, LayoutAndTextScaleWithTheWindowAndTheHostScale)
{
    Gui gui;
    plugin::RosinProcessor processor;
    std::unique_ptr<juce::AudioProcessorEditor> editor(processor.createEditorIfNeeded());
    auto& e = *static_cast<ui::RosinEditor*>(editor.get());
    float previous = 0.0f;
    for (const auto size : {juce::Point<int>(ui::RosinEditor::minWidth, ui::RosinEditor::minHeight),
                            juce::Point<int>(ui::RosinEditor::defaultWidth, ui::RosinEditor::defaultHeight), juce::Point<int>(1800, 1200)}) {
        e.setSize(size.x, size.y);
        EXPECT_GE(e.smallestTextHeight(), 11.0f) << size.x << "x" << size.y;
        EXPECT_GE(e.smallestTextHeight(), previous) << "text grows with the window";
        previous = e.smallestTextHeight();
        // Every control lies inside the window and no two visible controls overlap.
        std::vector<juce::Rectangle<int>> boxes;
        for (auto* c : e.getChildren())
            if (c->isVisible() && c->getWidth() > 0) {
                EXPECT_TRUE(e.getLocalBounds().contains(c->getBounds())) << c->getName() << " at " << size.x << "x" << size.y;
                boxes.push_back(c->getBounds());
            }
        int overlaps = 0;
        for (std::size_t i = 0; i < boxes.size(); ++i)
            for (std::size_t j = i + 1; j < boxes.size(); ++j)
                if (boxes[i].intersects(boxes[j])) {
                    ++overlaps;
                    ADD_FAILURE() << boxes[i].toString() << " overlaps " << boxes[j].toString();
                }
        EXPECT_EQ(overlaps, 0) << size.x << "x" << size.y;
    }
    EXPECT_GT(previous, 16.0f);

    // 200 %: a host's scale factor doubles every pixel, text included.
    e.setSize(ui::RosinEditor::defaultWidth, ui::RosinEditor::defaultHeight);
    e.setScaleFactor(2.0f);
    pump(100);
    const juce::Image big = e.createComponentSnapshot(e.getLocalBounds(), true, 2.0f);
    EXPECT_EQ(big.getWidth(), 2 * ui::RosinEditor::defaultWidth);
    EXPECT_GE(e.smallestTextHeight() * 2.0f, 22.0f);
    juce::PNGImageFormat png;
    juce::FileOutputStream out(artefacts().getChildFile("editor-200.png"));
    out.setPosition(0);
    out.truncate();
    ASSERT_TRUE(png.writeImageToStream(big, out));
    processor.editorBeingDeleted(editor.get());
}
