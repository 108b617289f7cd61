-- Neovim's own LSP client against crossrtd --lsp, headless: open a header whose class does not
-- translate for Vulkan, see the translator's diagnostics, fix the class in the buffer (unsaved),
-- see them clear. Run by lsp_neovim.py, which says where things are in the environment.
local server = os.getenv("CROSSRT_LSP_SERVER")
local work = os.getenv("CROSSRT_LSP_WORK")

local function finish(ok, message)
  io.stdout:write((ok and "OK: " or "FAIL: ") .. message .. "\n")
  io.stdout:flush()
  vim.cmd(ok and "qall!" or "cquit!")
end

vim.cmd("edit " .. work .. "/Scale.h")
local buf = vim.api.nvim_get_current_buf()
local client = vim.lsp.start_client({
  name = "crossrtd",
  cmd = { server, "--lsp", "--log", work .. "/nvim-lsp.log" },
  root_dir = work,
})
if not client then return finish(false, "the client did not start crossrtd") end
vim.lsp.buf_attach_client(buf, client)

if not vim.wait(60000, function() return #vim.diagnostic.get(buf) == 2 end, 20) then
  return finish(false, "no diagnostics in 60 s (saw " .. #vim.diagnostic.get(buf) .. ")")
end
for _, d in ipairs(vim.diagnostic.get(buf)) do
  if not d.message:find("has no size", 1, true) or d.source ~= "crossrt (vulkan)" then
    return finish(false, "unexpected diagnostic: " .. d.message .. " from " .. tostring(d.source))
  end
  io.stdout:write("neovim shows line " .. (d.lnum + 1) .. ": " .. d.message:gsub("\n.*", "") .. " [" .. d.source .. "]\n")
end

-- The fix, typed into the buffer and not saved.
local lines = vim.api.nvim_buf_get_lines(buf, 0, -1, false)
for i, line in ipairs(lines) do
  if line:find("virtual void Run(", 1, true) then
    local fixed = line:gsub("const float%* in", '[[crossrt::size("n")]] const float* in'):gsub("float%* out", '[[crossrt::size("n")]] float* out')
    vim.api.nvim_buf_set_lines(buf, i - 1, i, false, { fixed })
  end
end
if not vim.wait(60000, function() return #vim.diagnostic.get(buf) == 0 end, 20) then
  return finish(false, "the diagnostics did not clear after the fix (" .. #vim.diagnostic.get(buf) .. " left)")
end
-- Neovim clears a client's diagnostics when the client exits too: the server must still be there,
-- and answer.
local c = vim.lsp.get_client_by_id(client)
if not c or c.is_stopped() then return finish(false, "crossrtd went away after the edit") end
local answered = c.request_sync("textDocument/codeLens", { textDocument = vim.lsp.util.make_text_document_params(buf) }, 60000, buf)
if not answered or answered.err then
  return finish(false, "crossrtd did not answer after the edit: " .. vim.inspect(answered and answered.err))
end
vim.lsp.stop_client(client)
finish(true, "Neovim showed the translator's diagnostics and cleared them after the fix")
